// check_pass_order: the start-up check that every pass of a view reads only what the frame
// provides or an earlier pass wrote, writes one target, and never writes what the frame provides.
// Passes here are declarations alone (no GL).
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "server/render/pass.hpp"

namespace downpour::render {
namespace {

class Declared final : public Pass {
 public:
  explicit Declared(PassDecl decl) : decl_(std::move(decl)) {}
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext&, const FrameResources&) override {}

 private:
  PassDecl decl_;
};

Declared pass(std::string name, std::vector<Resource> reads, std::vector<Resource> writes) {
  return Declared(PassDecl{std::move(name), std::move(reads), std::move(writes), {}});
}

// The error check_pass_order throws for `passes`, or "" when it accepts them.
std::string error_of(const std::vector<Pass*>& passes) {
  try {
    check_pass_order("TEST", passes);
  } catch (const std::logic_error& e) {
    return e.what();
  }
  return "";
}

TEST(PassOrderTest, ALayerIsReadOnlyAfterAPassWroteIt) {
  Declared water =
      pass("water", {Resource::kGlassSurface, Resource::kEnvironment}, {Resource::kGlassLayer});
  Declared composite =
      pass("composite", {Resource::kGlassLayer}, {Resource::kViewColour, Resource::kViewDepth});
  EXPECT_EQ(error_of({&water, &composite}), "");
  EXPECT_EQ(error_of({&composite, &water}),
            "TEST view, pass composite: reads before anything writes " +
                std::string(resource_name(Resource::kGlassLayer)));
}

TEST(PassOrderTest, TheFramesOwnInputsAreThereFromTheStartAndNoPassWritesThem) {
  Declared reader = pass("reader",
                         {Resource::kRoadWater, Resource::kRoadReflection, Resource::kViewColour,
                          Resource::kViewDepth},
                         {Resource::kViewColour});
  EXPECT_EQ(error_of({&reader}), "");
  Declared writer = pass("writer", {}, {Resource::kEnvironment});
  EXPECT_EQ(error_of({&writer}), "TEST view, pass writer: cannot write " +
                                     std::string(resource_name(Resource::kEnvironment)));
}

TEST(PassOrderTest, APassWritesOneTarget) {
  Declared none = pass("none", {}, {});
  EXPECT_EQ(error_of({&none}), "TEST view, pass none: must write one target");
  Declared two = pass("two", {}, {Resource::kGlassLayer, Resource::kSprayLayer});
  EXPECT_EQ(error_of({&two}), "TEST view, pass two: must write one target");
  Declared layer_and_view = pass("mixed", {}, {Resource::kSprayLayer, Resource::kViewColour});
  EXPECT_EQ(error_of({&layer_and_view}), "TEST view, pass mixed: must write one target");
}

TEST(PassOrderTest, ATargetDrawnAgainstAnothersDepthComesAfterThePassThatWroteIt) {
  // The spray's shading tests against the mask its maps pass leaves as the maps' depth.
  Declared maps = pass("maps", {}, {Resource::kSprayMaps});
  Declared shade = pass("shade", {Resource::kSprayMaps}, {Resource::kSprayLayer});
  Declared haze_over = pass("haze over", {}, {Resource::kSprayLayer});
  EXPECT_EQ(error_of({&maps, &shade}), "");
  EXPECT_EQ(error_of({&haze_over}),
            "TEST view, pass haze over: draws against the depth of what no pass wrote yet: " +
                std::string(resource_name(Resource::kSprayMaps)));
}

// The error check_frame_pass throws for `p`, or "" when it accepts it.
std::string frame_error_of(const Pass& p) {
  try {
    check_frame_pass(p);
  } catch (const std::logic_error& e) {
    return e.what();
  }
  return "";
}

TEST(PassOrderTest, AFramePassDrawsOneResourceOfTheFramesStartFromTheOthers) {
  Declared reflection = pass("reflection", {Resource::kLampMap}, {Resource::kRoadReflection});
  EXPECT_EQ(frame_error_of(reflection), "");
  Declared to_view = pass("to view", {}, {Resource::kViewColour});
  EXPECT_EQ(frame_error_of(to_view),
            "frame pass to view: must write one resource of the frame's start");
  Declared reads_view = pass("reads view", {Resource::kViewDepth}, {Resource::kLampMap});
  EXPECT_EQ(frame_error_of(reads_view), "frame pass reads view: reads " +
                                            std::string(resource_name(Resource::kViewDepth)) +
                                            ", which is not there before it");
}

TEST(PassOrderTest, EveryResourceIsInTheTableInItsOrderAndEveryTransientHasASize) {
  for (std::size_t i = 0; i < kResourceCount; ++i) {
    const ResourceInfo& info = resource_info(static_cast<Resource>(i));
    EXPECT_EQ(static_cast<std::size_t>(info.resource), i);
    EXPECT_FALSE(info.name.empty());
    // A view target is no transient; a resource that borrows a depth is a transient of the same
    // scale as its owner.
    if (info.view_target) {
      EXPECT_EQ(info.scale, kNotTransient) << info.name;
    }
    if (info.depth_from && *info.depth_from != info.resource) {
      EXPECT_EQ(resource_info(*info.depth_from).scale, info.scale) << info.name;
      EXPECT_EQ(resource_info(*info.depth_from).depth_from, info.depth_from) << info.name;
    }
  }
}

}  // namespace
}  // namespace downpour::render
