// An encoded frame as it leaves the pipeline, shared (read-only) by every reader that gets it.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "server/sim/types.hpp"

namespace downpour::session {

struct FrameStats {
  double render_ms = 0.0;
  double readback_ms = 0.0;
  double encode_ms = 0.0;
  double latency_ms = 0.0;  // from the arrival of the inputs the tick consumed to the encoded frame
  std::uint32_t drops_on_glass = 0;
  double glass_wet_fraction = 0.0;
  double view_wet_fraction = 0.0;
  std::uint32_t rain_streaks = 0;  // rain streaks drawn in this view
  double visibility_m = 0.0;       // through the fog and the rain
  // The visible road in each state of the water model, in RoadState's order (all 0: no road in
  // sight).
  std::array<double, 4> road_states{};
  // A client-background view: the frames it drew over a picture already drawn, or none yet.
  std::uint64_t background_repeats = 0;
};

struct EncodedFrame {
  std::string session_id;
  std::uint64_t frame_number = 0;
  double sim_time_s = 0.0;
  double client_time_s = 0.0;
  sim::View view = sim::View::kCockpit;
  int width = 0;
  int height = 0;
  std::string jpeg;
  // The ground truth the view asked for (sim::Outputs), from the same tick; empty otherwise.
  std::string clean_jpeg;
  std::string water_mask_png;  // 8-bit grey
  std::string depth_png;       // 16-bit grey, centimetres
  FrameStats stats;
  std::array<sim::TireWater, sim::kTires> tires{};  // the tick's: the road's water under the tires
  sim::EgoPlace ego_place;                          // the tick's
};

using FramePtr = std::shared_ptr<const EncodedFrame>;

// Why a session ended, so that its streams and its waiting steps end with a status that says so.
enum class EndReason {
  kClosed,        // CloseSession
  kIdle,          // no client was heard for the server's idle timeout
  kFailed,        // a frame of it failed (the message says how); the others go on
  kShuttingDown,  // the server is draining
  kCancelled,     // (a step only) its call was cancelled or ran out of time before it started
};
struct SessionEnd {
  EndReason reason = EndReason::kClosed;
  std::string message;
};

// Something that receives a session's frames as they are encoded: a WatchFrames reader, a
// realtime Drive stream. Called on encoder threads; must not block.
class FrameSink {
 public:
  virtual ~FrameSink() = default;
  virtual void on_frame(const FramePtr& frame) = 0;
  virtual void on_session_closed(const SessionEnd& end) = 0;
};

}  // namespace downpour::session
