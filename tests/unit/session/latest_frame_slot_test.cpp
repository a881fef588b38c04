#include "server/session/latest_frame_slot.hpp"

#include <atomic>
#include <memory>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace downpour::session {
namespace {

FramePtr make_frame(std::uint64_t number, sim::View view) {
  auto f = std::make_shared<EncodedFrame>();
  f->frame_number = number;
  f->view = view;
  return f;
}

TEST(LatestFrameSlotTest, TakeOnEmptyReturnsNull) {
  LatestFrameSlot slot;
  EXPECT_EQ(slot.take(), nullptr);
  EXPECT_EQ(slot.drops(), 0u);
}

TEST(LatestFrameSlotTest, TakesLowestFrameNumberFirstAcrossViews) {
  LatestFrameSlot slot;
  EXPECT_TRUE(slot.put(make_frame(7, sim::View::kRoad)).was_empty);
  EXPECT_FALSE(slot.put(make_frame(5, sim::View::kRain)).was_empty);
  EXPECT_FALSE(slot.put(make_frame(6, sim::View::kCockpit)).was_empty);
  EXPECT_FALSE(slot.put(make_frame(9, sim::View::kWindshield)).was_empty);
  std::vector<std::uint64_t> order;
  while (FramePtr f = slot.take()) order.push_back(f->frame_number);
  EXPECT_EQ(order, (std::vector<std::uint64_t>{5, 6, 7, 9}));
  EXPECT_EQ(slot.drops(), 0u);
  EXPECT_EQ(slot.take(), nullptr);
}

TEST(LatestFrameSlotTest, ATicksViewsAreTakenTogetherOnceAllHaveCome) {
  LatestFrameSlot slot;
  slot.put(make_frame(4, sim::View::kRoad));
  EXPECT_TRUE(slot.take_tick(2).empty()) << "the tick's COCKPIT frame is still on its way";
  slot.put(make_frame(4, sim::View::kCockpit));
  const std::vector<FramePtr> tick = slot.take_tick(2);
  ASSERT_EQ(tick.size(), 2u);
  EXPECT_EQ(tick[0]->frame_number, 4u);
  EXPECT_EQ(tick[1]->frame_number, 4u);
  EXPECT_NE(tick[0]->view, tick[1]->view);
  EXPECT_TRUE(slot.take_tick(2).empty());
  // A reader that fell behind: ROAD's frame 5 was replaced by 6, so tick 5 can never be whole;
  // its COCKPIT frame goes alone, then tick 6 once whole.
  slot.put(make_frame(5, sim::View::kCockpit));
  slot.put(make_frame(5, sim::View::kRoad));
  slot.put(make_frame(6, sim::View::kRoad));
  const std::vector<FramePtr> partial = slot.take_tick(2);
  ASSERT_EQ(partial.size(), 1u);
  EXPECT_EQ(partial[0]->frame_number, 5u);
  EXPECT_EQ(partial[0]->view, sim::View::kCockpit);
  EXPECT_TRUE(slot.take_tick(2).empty());
  slot.put(make_frame(6, sim::View::kCockpit));
  EXPECT_EQ(slot.take_tick(2).size(), 2u);
  EXPECT_EQ(slot.drops(), 1u);
}

TEST(LatestFrameSlotTest, WasEmptyAgainAfterEverythingIsTaken) {
  LatestFrameSlot slot;
  EXPECT_TRUE(slot.put(make_frame(1, sim::View::kCockpit)).was_empty);
  ASSERT_NE(slot.take(), nullptr);
  EXPECT_TRUE(slot.put(make_frame(2, sim::View::kCockpit)).was_empty);
}

TEST(LatestFrameSlotTest, NewerFrameOfTheSameViewReplacesAndCountsADrop) {
  LatestFrameSlot slot;
  const LatestFrameSlot::PutResult first = slot.put(make_frame(1, sim::View::kCockpit));
  EXPECT_FALSE(first.dropped);
  const LatestFrameSlot::PutResult second = slot.put(make_frame(2, sim::View::kCockpit));
  EXPECT_TRUE(second.dropped);
  EXPECT_FALSE(second.was_empty);
  EXPECT_EQ(slot.drops(), 1u);
  const FramePtr f = slot.take();
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->frame_number, 2u);
  EXPECT_EQ(slot.take(), nullptr);
  // A frame of another view is not a drop.
  EXPECT_FALSE(slot.put(make_frame(3, sim::View::kRoad)).dropped);
  EXPECT_EQ(slot.drops(), 1u);
}

TEST(LatestFrameSlotTest, MemoryStaysBoundedForAReaderThatNeverTakes) {
  LatestFrameSlot slot;
  std::vector<FramePtr> last_per_view(sim::kViewCount);
  for (std::uint64_t n = 1; n <= 10000; ++n) {
    const auto view = static_cast<sim::View>(n % sim::kViewCount);
    FramePtr frame = make_frame(n, view);
    FramePtr& previous = last_per_view[static_cast<int>(view)];
    slot.put(frame);
    if (previous) {
      // The replaced frame is no longer held by the slot: only this test holds it.
      ASSERT_EQ(previous.use_count(), 1) << "frame " << previous->frame_number;
    }
    ASSERT_EQ(frame.use_count(), 2);  // this test and the slot
    previous = std::move(frame);
  }
  EXPECT_EQ(slot.drops(), 10000u - sim::kViewCount);
  int pending = 0;
  while (slot.take()) ++pending;
  EXPECT_EQ(pending, sim::kViewCount);
}

TEST(LatestFrameSlotTest, ConcurrentPutsAndTakesAddUp) {
  LatestFrameSlot slot;
  constexpr int kPuts = 20000;
  std::atomic<bool> done{false};
  std::uint64_t takes = 0;
  std::uint64_t put_drops = 0;
  std::thread reader([&] {
    std::uint64_t last[sim::kViewCount] = {0, 0, 0, 0};
    for (;;) {
      const bool finished = done.load();
      while (FramePtr f = slot.take()) {
        ++takes;
        // Per view, frames arrive in increasing order: an older frame never follows a newer one.
        EXPECT_GT(f->frame_number, last[static_cast<int>(f->view)]);
        last[static_cast<int>(f->view)] = f->frame_number;
      }
      if (finished) break;
      std::this_thread::yield();
    }
  });
  for (std::uint64_t n = 1; n <= kPuts; ++n) {
    if (slot.put(make_frame(n, static_cast<sim::View>(n % 3))).dropped) ++put_drops;
  }
  done.store(true);
  reader.join();
  std::uint64_t still_pending = 0;
  while (slot.take()) ++still_pending;
  EXPECT_EQ(still_pending, 0u);  // the reader drained after the last put
  EXPECT_EQ(put_drops, slot.drops());
  EXPECT_EQ(static_cast<std::uint64_t>(kPuts), takes + slot.drops() + still_pending);
}

}  // namespace
}  // namespace downpour::session
