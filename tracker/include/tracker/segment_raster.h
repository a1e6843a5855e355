#pragma once
// The tracker's input: a visual hull SegmentSet (hull/segment_set.h) rasterised into an
// OccupancyGrid at the column resolution.
//
// The grid's voxels coincide with the hull's cells across the columns (cell (i, j) of the
// SegmentSet is voxel i along axis u, j along axis v); along the continuous axis the voxel size
// is the finer of the two column spacings (so a square column grid gives cubic voxels), the
// lattice starting at the box's t_min. A voxel holds the covered fraction of its length along
// the continuous axis (sum over the intervals in it, in 1/255, saturating), so the segments'
// continuous ends survive. The grid covers only the occupied part of the box (every voxel
// outside it is empty, which the head search assumes); an empty hull gives an empty grid.

#include "hull/segment_set.h"
#include "tracker/occupancy.h"

namespace studio::tracker {

// Rasterises into *grid, reusing its memory.
void rasterise(const hull::SegmentSet& set, OccupancyGrid* grid);
inline OccupancyGrid rasterise(const hull::SegmentSet& set) {
  OccupancyGrid g;
  rasterise(set, &g);
  return g;
}

}  // namespace studio::tracker
