#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "server/render/gl/gl_objects.hpp"
#include "server/render/model_meshes.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

// The cabin around the driver's eye: dashboard edge, A-pillars, roof liner and mirror, dark
// silhouettes framing the view through the windshield, built around the glass of the scene; or
// the cabin model the session names.
//
// It is drawn in the car's frame (cabin.vert) and lit by the atmosphere's light turned into that
// frame, so that for a camera fixed in the car its picture changes only with the light. Where the
// renderer keeps its picture (llvmpipe, which pays as much for a cabin pixel as for any other: 1.5
// ms of a 640x360 frame, 5 at 1280x720), the light is rounded (the world's up and the sun's
// direction to 1/64 a component, radiances to 1/128 of themselves; no sun's direction where there
// is no sun), the cabin's picture on a cleared view (colour and depth) is kept under
// everything it was drawn with, and a view whose frame would draw the same gets it back by a copy
// in place of its clear and the draw (restore()). Drawn or copied, the pixels are the same.
class CockpitPass final : public Pass {
 public:
  // keep_pictures: keep the cabin's pictures and restore them (llvmpipe's choice).
  CockpitPass(SharedResources& shared, bool keep_pictures);
  ~CockpitPass() override;
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;
  // At a view's start, in place of its clear, with nothing drawn into its target yet in this frame
  // and nothing drawing into it still from an earlier one: the kept picture of this frame's cabin
  // copied into the view's colour and depth, if there is one ready. Then execute() draws nothing.
  bool restore(const FrameContext& frame, const FrameResources& resources);
  // Lets go of the kept pictures (Renderer::release_shared_targets).
  void release();

  // How many frames restored the cabin, and drew it (and how many of those kept the picture).
  struct Counts {
    std::uint64_t restored = 0, drawn = 0, kept = 0;
  };
  const Counts& counts() const { return counts_; }

 private:
  // What a picture of the cabin is drawn with: the mesh, the view's size, the camera in the car's
  // frame and the light; equal keys, equal pictures.
  struct Key {
    std::uint64_t mesh = 0;  // ModelMesh::serial
    int width = 0, height = 0;
    // Clip from car; the eye, up, the sun's direction, ambient, the sun's radiance, the horizon's.
    std::array<float, 16 + 6 * 3> numbers{};
    bool operator==(const Key&) const = default;
  };
  struct Kept;
  Key key_of(const FrameContext& frame, const ModelMesh& mesh) const;
  const ModelMesh& mesh_of(const FrameContext& frame);
  void draw(const ModelMesh& mesh, const Key& key);

  const PassDecl decl_{"cockpit",
                       {},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, true, Blend::kOff}};
  ShaderProgram program_;
  ModelUniforms uniforms_;
  Uniform u_clip_from_car_, u_eye_, u_up_, u_sun_dir_, u_ambient_, u_sun_radiance_, u_sky_horizon_;
  sim::GlassConfig built_for_;
  ModelMesh interior_;  // the built-in cabin round the glass
  ModelMeshes named_;   // the cabin models sessions name
  bool keep_pictures_;
  std::vector<std::unique_ptr<Kept>> kept_;  // the latest few, the most recently used first
  GLuint restored_into_ = 0;                 // the view colour restore() filled, until execute()
  bool last_kept_used_ = true;               // whether a frame has restored the last picture kept
  std::uint64_t drawn_at_keep_ = 0;          // counts().drawn when it was kept
  Counts counts_;
};

}  // namespace downpour::render
