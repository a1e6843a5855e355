// BalanceWorker (preview/node/balance_worker.h): jobs pooled on its thread, the estimate read as
// a snapshot, a refused job not counted, a restart forgetting the pool, a job in hand finished
// at destruction.
#include "balance_worker.h"

#include <gtest/gtest.h>

namespace studio::preview {
namespace {

BalanceWorker::Job job(const std::string& a, const std::string& b) {
  BalanceWorker::Job j;
  for (const std::string id : {"cam0", "cam1"}) {
    Camera c;
    c.id = id;
    c.width = 8;
    c.height = 6;
    c.intrinsics.fx = c.intrinsics.fy = 10;
    j.rig[id] = c;
  }
  j.cameras = {a, b};
  for (int i = 0; i < 2; ++i) {
    j.images.push_back({8, 6, 0, std::vector<uint8_t>(8 * 6 * 3, 100)});
    j.masks.push_back(RunMask::from_mask(Mask(8, 6).view()));
  }
  return j;
}

TEST(BalanceWorker, PoolsOnItsThreadAndCountsOnlyWhatItPooled) {
  BalanceWorker w;
  EXPECT_EQ(w.snapshot().balance.frames, 0);
  ASSERT_TRUE(w.submit(job("cam0", "cam1")));
  w.wait_idle();
  EXPECT_EQ(w.pooled(), 1u);
  const BalanceSnapshot s = w.snapshot();
  EXPECT_EQ(s.balance.frames, 1);
  EXPECT_EQ(s.cameras, (std::vector<std::string>{"cam0", "cam1"}));
  EXPECT_EQ(s.gains("cam0"), Eigen::Vector3f::Ones());
  // A camera outside the rig: refused by the estimate (logged), nothing pooled.
  ASSERT_TRUE(w.submit(job("cam0", "cam7")));
  w.wait_idle();
  EXPECT_EQ(w.pooled(), 1u);
  EXPECT_EQ(w.snapshot().balance.frames, 1);
}

TEST(BalanceWorker, RestartForgetsWhatWasPooled) {
  BalanceWorker w;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(w.submit(job("cam0", "cam1")));
    w.wait_idle();
  }
  EXPECT_EQ(w.snapshot().balance.frames, 3);
  w.restart();  // at once: an empty estimate
  EXPECT_EQ(w.snapshot().balance.frames, 0);
  EXPECT_TRUE(w.snapshot().cameras.empty());
  ASSERT_TRUE(w.submit(job("cam0", "cam1")));
  w.wait_idle();
  EXPECT_EQ(w.snapshot().balance.frames, 1);  // pooled afresh, not the 4th
  // A restart while a job may be in hand: that job does not reach the snapshot.
  ASSERT_TRUE(w.submit(job("cam0", "cam1")));
  w.restart();
  w.wait_idle();
  EXPECT_EQ(w.snapshot().balance.frames, 0);
  ASSERT_TRUE(w.submit(job("cam0", "cam1")));
  w.wait_idle();
  EXPECT_EQ(w.snapshot().balance.frames, 1);
}

TEST(BalanceWorker, FinishesTheJobInHandWhenDestroyed) {
  auto w = std::make_unique<BalanceWorker>();
  ASSERT_TRUE(w->submit(job("cam0", "cam1")));
  w.reset();  // joins after pooling it; must not hang or crash
  SUCCEED();
}

}  // namespace
}  // namespace studio::preview
