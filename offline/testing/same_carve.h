#pragma once
// The check both carve-equality tests make (tests only): judging only the voxels whose verdict
// could change (CarveOptions::incremental) carves exactly what judging every surface voxel every
// iteration carves, with fewer judgements (the control that it skipped any), and the case carves
// something over several iterations (else the comparison says nothing).
#include <gtest/gtest.h>

#include "offline/photo_carve.h"

namespace studio::offline::testing {

inline void expect_same_carve(const CarveResult& every, const CarveResult& incremental) {
  EXPECT_GT(every.carved, 0u);
  EXPECT_GT(every.iterations, 2);
  EXPECT_EQ(every.set, incremental.set);
  EXPECT_EQ(every.carved, incremental.carved);
  EXPECT_EQ(every.iterations, incremental.iterations);
  EXPECT_LT(incremental.judged, every.judged);
}

}  // namespace studio::offline::testing
