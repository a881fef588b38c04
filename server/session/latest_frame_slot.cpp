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

std::uint64_t LatestFrameSlot::drops() const {
  std::lock_guard lock(mutex_);
  return drops_;
}

}  // namespace downpour::session
