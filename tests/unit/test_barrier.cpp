// The frame barrier's bookkeeping: master/barrier.h.

#include <gtest/gtest.h>

#include <vector>

#include "master/barrier.h"

namespace optique::master {
namespace {

using Slots = std::vector<std::size_t>;

TEST(Barrier, InactiveBeforeBegin) {
  Barrier b;
  EXPECT_FALSE(b.active());
  EXPECT_FALSE(b.complete());
}

TEST(Barrier, CompleteOnlyWhenAllExpectedAreReady) {
  Barrier b;
  b.begin(7, {0, 2, 3});
  EXPECT_TRUE(b.active());
  EXPECT_EQ(b.frame(), 7u);
  EXPECT_FALSE(b.complete());
  EXPECT_EQ(b.waiting_for(), (Slots{0, 2, 3}));

  EXPECT_TRUE(b.ready(2));
  EXPECT_FALSE(b.complete());
  EXPECT_EQ(b.waiting_for(), (Slots{0, 3}));
  EXPECT_TRUE(b.ready(0));
  EXPECT_FALSE(b.complete());
  EXPECT_TRUE(b.ready(3));
  EXPECT_TRUE(b.complete());
  EXPECT_TRUE(b.waiting_for().empty());
}

TEST(Barrier, ReadyTwiceCountsOnce) {
  Barrier b;
  b.begin(1, {0, 1});
  EXPECT_TRUE(b.ready(0));
  EXPECT_FALSE(b.ready(0));
  EXPECT_FALSE(b.complete());
  EXPECT_EQ(b.waiting_for(), (Slots{1}));
}

TEST(Barrier, LeaveOfAWaitedNodeCompletesIt) {
  Barrier b;
  b.begin(3, {4, 5});
  EXPECT_TRUE(b.ready(4));
  EXPECT_FALSE(b.complete());
  b.leave(5);
  EXPECT_TRUE(b.complete());
  EXPECT_TRUE(b.waiting_for().empty());
}

TEST(Barrier, LeaveOfEveryoneCompletesIt) {
  Barrier b;
  b.begin(3, {1, 2});
  b.leave(2);
  EXPECT_FALSE(b.complete());
  b.leave(1);
  EXPECT_TRUE(b.complete());
}

TEST(Barrier, LeaveOfANonWaitedNodeChangesNothing) {
  Barrier b;
  b.begin(3, {1, 2});
  b.leave(9);
  EXPECT_FALSE(b.complete());
  EXPECT_EQ(b.waiting_for(), (Slots{1, 2}));
}

TEST(Barrier, ReadyOfANonWaitedNodeReturnsFalse) {
  Barrier b;
  b.begin(2, {0, 1});
  EXPECT_FALSE(b.ready(5));
  EXPECT_FALSE(b.complete());
  EXPECT_EQ(b.waiting_for(), (Slots{0, 1}));
  // Nor does a node that left count when it reports late.
  b.leave(1);
  EXPECT_FALSE(b.ready(1));
  EXPECT_TRUE(b.ready(0));
  EXPECT_TRUE(b.complete());
}

TEST(Barrier, BeginWithNoNodesIsCompleteImmediately) {
  Barrier b;
  b.begin(0, {});
  EXPECT_TRUE(b.active());
  EXPECT_TRUE(b.complete());
}

TEST(Barrier, EndDeactivates) {
  Barrier b;
  b.begin(0, {});
  b.end();
  EXPECT_FALSE(b.active());
  EXPECT_FALSE(b.complete());
}

TEST(Barrier, BeginReplacesThePreviousFrame) {
  Barrier b;
  b.begin(10, {0, 1, 2});
  EXPECT_TRUE(b.ready(1));
  b.end();
  b.begin(11, {0, 1});
  EXPECT_EQ(b.frame(), 11u);
  EXPECT_EQ(b.waiting_for(), (Slots{0, 1}));
  EXPECT_FALSE(b.complete());
  EXPECT_TRUE(b.ready(1));   // waited for again in the new frame
  EXPECT_FALSE(b.ready(2));  // not in the new frame
  EXPECT_TRUE(b.ready(0));
  EXPECT_TRUE(b.complete());
}

}  // namespace
}  // namespace optique::master
