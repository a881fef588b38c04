#include "server/session/latest_frame_slot.hpp"

namespace downpour::session {

LatestFrameSlot::PutResult LatestFrameSlot::put(FramePtr frame) {
  std::lock_guard lock(mutex_);
  PutResult result{true, false};
  for (const FramePtr& p : pending_) result.was_empty = result.was_empty && !p;
  FramePtr& place = pending_[static_cast<int>(frame->view)];
  if (place) {
    ++drops_;
    result.dropped = true;
  }
  place = std::move(frame);
  return result;
}

FramePtr LatestFrameSlot::take() {
  std::lock_guard lock(mutex_);
  FramePtr* oldest = nullptr;
  for (FramePtr& p : pending_) {
    if (p && (!oldest || p->frame_number < (*oldest)->frame_number)) oldest = &p;
  }
  if (!oldest) return nullptr;
  FramePtr out = std::move(*oldest);
  oldest->reset();
  return out;
}

std::vector<FramePtr> LatestFrameSlot::take_tick(std::size_t views) {
  std::lock_guard lock(mutex_);
  std::vector<FramePtr> out;
  const FramePtr* oldest = nullptr;
  bool later = false;
  for (const FramePtr& p : pending_) {
    if (p && (!oldest || p->frame_number < (*oldest)->frame_number)) oldest = &p;
  }
  if (!oldest) return out;
  const std::uint64_t tick = (*oldest)->frame_number;
  std::size_t count = 0;
  for (const FramePtr& p : pending_) {
    if (!p) continue;
    count += p->frame_number == tick;
    later = later || p->frame_number > tick;
  }
  if (count < views && !later) return out;  // the tick's other views are still on their way
  for (FramePtr& p : pending_) {
    if (p && p->frame_number == tick) out.push_back(std::move(p)), p.reset();
  }
  return out;
}

std::uint64_t LatestFrameSlot::drops() const {
  std::lock_guard lock(mutex_);
  return drops_;
}

}  // namespace downpour::session
