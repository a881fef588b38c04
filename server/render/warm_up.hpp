// Before a server takes sessions: the programs and states the views' passes pick in the common
// scenes drawn once, small, so that llvmpipe compiles their shader variants then and not in a
// session's stream (what is still left: docs/operations.md). A
// variant first needed mid-stream stalls the render loop, and with it every session, for the
// compile (100-250 ms each on the development machine, without Mesa's shader cache on disk: a
// fresh machine's first run, a container's every start): spray behind a truck, puddles with their
// mirror and ripples, the lamps at night, the relief shadows under the sun.
#pragma once

#include <cstdint>
#include <vector>

namespace downpour::sim {
struct SceneState;
struct ViewSpec;
}  // namespace downpour::sim

namespace downpour::render {

class Renderer;
class RenderSession;
struct GroundTruthPixels;

// One tick of the first `count` of a session's `views`, as a session's tick draws them: each
// begun, then each ended, then each read back (into `pixels` and `truth`, in turn). Throws
// std::runtime_error if a frame comes back the wrong size. (The warm-up's and its tests'.)
void draw_tick(Renderer& renderer, RenderSession& session, const std::vector<sim::ViewSpec>& views,
               std::size_t count, const sim::SceneState& scene, std::vector<std::uint8_t>& pixels,
               GroundTruthPixels& truth);

// How much the warm-up draws (the server's --warm-up).
enum class WarmUp {
  // The built-in scenes in every view at 320x180, as sessions draw them: a drop on dry glass;
  // heavy rain with water standing on the road behind a truck, by day, at night and under a low
  // sun, each from a session's start (the environment probe drawn whole, then a face on its own)
  // and, by day and at night, a second on (drops, spray; at night on until each face of the
  // environment has been drawn on its own), then over a client's pictures with and without their
  // depth. 1.7-2 s on the development machine with Mesa's shader cache on disk
  // (5-6 s under ASan), 6 s without.
  kFull,
  // A drop on dry glass in every view at 64x36: proves the context, the programs and the
  // readback, and leaves the variants the sessions' scenes pick to be compiled when first drawn
  // (for servers whose streams are not watched for stalls: the tests of the protocol).
  kMinimal,
};

// Draws what `level` says. Throws std::runtime_error if a frame comes back empty or the wrong
// size.
void warm_up(Renderer& renderer, WarmUp level = WarmUp::kFull);

}  // namespace downpour::render
