// A reader's mailbox: the latest frame per view, nothing older. A new frame replaces an unsent
// one, which counts as a drop; so memory stays bounded however slow the reader is.
#pragma once

#include <array>
#include <cstdint>
#include <mutex>
#include <vector>

#include "server/session/frame.hpp"

namespace downpour::session {

class LatestFrameSlot {
 public:
  struct PutResult {
    bool was_empty = false;  // the reader may need waking
    bool dropped = false;    // an unsent frame of the same view was replaced
  };
  PutResult put(FramePtr frame);
  // The oldest pending frame (lowest frame number) across views, or null; clears its place.
  FramePtr take();
  // The oldest tick's frames, in view order, once the tick is whole (`views` of them) or can no
  // longer be (a view has a later frame pending: the tick's was taken or replaced); else none.
  std::vector<FramePtr> take_tick(std::size_t views);
  std::uint64_t drops() const;

 private:
  mutable std::mutex mutex_;
  std::array<FramePtr, sim::kViewCount> pending_;  // guarded by mutex_
  std::uint64_t drops_ = 0;                        // guarded by mutex_
};

}  // namespace downpour::session
