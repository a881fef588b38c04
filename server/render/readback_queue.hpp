// Views' pixels on their way back from the GPU, in the order they were rendered, each with what its
// caller needs to know of it (a Payload). Readbacks that are ready are handed on; one that is not
// ready by the next collect() is waited for then, since each view target has two readback slots.
// Render thread only.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "server/render/renderer.hpp"

namespace downpour::render {

template <typename Payload>
class ReadbackQueue {
 public:
  // Where the pixel buffers come from (an encoder pool recycles them): a buffer of `bytes`.
  using BufferSource = std::function<std::vector<std::uint8_t>(std::size_t bytes)>;

  ReadbackQueue(Renderer& renderer, BufferSource buffers)
      : renderer_(renderer), buffers_(std::move(buffers)) {}

  void push(PendingReadback readback, Payload payload) {
    entries_.push_back({readback, std::move(payload), false});
  }

  // Hands each finished readback to take(payload, pixels, truth, wait_ms), pixels RGBA8 rows
  // bottom-up and truth the ground truth its view asked for (GroundTruthPixels):
  // those that are ready, those left from an earlier call (waiting for them), or all of them. A
  // readback that fails (the GPU's fence past its deadline, a buffer that cannot be mapped or
  // allocated) goes to fail(payload, what) instead, and the others go on.
  template <typename Take, typename Fail>
  void collect(bool all, Take&& take, Fail&& fail) {
    std::vector<Entry> waiting;
    for (Entry& e : entries_) {
      if (!all && !e.from_earlier_call && !renderer_.is_ready(e.readback)) {
        e.from_earlier_call = true;
        waiting.push_back(std::move(e));
        continue;
      }
      const auto t0 = std::chrono::steady_clock::now();
      std::vector<std::uint8_t> pixels;
      GroundTruthPixels truth;
      try {
        const std::size_t bytes =
            static_cast<std::size_t>(e.readback.width) * e.readback.height * 4;
        pixels = buffers_(bytes);
        if (e.readback.outputs.needs_clean()) truth.clean = buffers_(bytes);
        renderer_.finish(e.readback, pixels, &truth);
      } catch (const std::exception& error) {
        fail(std::move(e.payload), error.what());
        continue;
      }
      const double wait_ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      take(std::move(e.payload), std::move(pixels), std::move(truth), wait_ms);
    }
    entries_ = std::move(waiting);
  }

  bool empty() const { return entries_.empty(); }
  // Whether a readback of this session's targets is still in flight (its targets must live).
  bool holds(const RenderSession* session) const {
    for (const Entry& e : entries_) {
      if (e.readback.session == session) return true;
    }
    return false;
  }

 private:
  struct Entry {
    PendingReadback readback;
    Payload payload;
    bool from_earlier_call = false;
  };
  Renderer& renderer_;
  BufferSource buffers_;
  std::vector<Entry> entries_;
};

}  // namespace downpour::render
