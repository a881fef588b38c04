#include "server/rpc/convert.hpp"

namespace downpour::rpc {

v1::View to_proto(sim::View view) {
  switch (view) {
    case sim::View::kCockpit:
      return v1::VIEW_COCKPIT;
    case sim::View::kRoad:
      return v1::VIEW_ROAD;
    case sim::View::kWindshield:
      return v1::VIEW_WINDSHIELD;
    case sim::View::kRain:
      return v1::VIEW_RAIN;
  }
  return v1::VIEW_UNSPECIFIED;
}

v1::RoadState to_proto(sim::RoadState state) {
  switch (state) {
    case sim::RoadState::kDry:
      return v1::ROAD_DRY;
    case sim::RoadState::kWet:
      return v1::ROAD_WET;
    case sim::RoadState::kDrench:
      return v1::ROAD_DRENCH;
    case sim::RoadState::kPuddle:
      return v1::ROAD_PUDDLE;
  }
  return v1::ROAD_STATE_UNSPECIFIED;
}

void fill_frame(const session::EncodedFrame& f, std::uint64_t reader_drops, v1::Frame* out) {
  out->set_session_id(f.session_id);
  out->set_frame_number(f.frame_number);
  out->set_sim_time_s(f.sim_time_s);
  out->set_client_time_s(f.client_time_s);
  out->set_view(to_proto(f.view));
  out->set_width(static_cast<std::uint32_t>(f.width));
  out->set_height(static_cast<std::uint32_t>(f.height));
  out->set_jpeg(f.jpeg);
  if (!f.clean_jpeg.empty()) out->set_clean_jpeg(f.clean_jpeg);
  if (!f.water_mask_png.empty()) out->set_water_mask_png(f.water_mask_png);
  if (!f.depth_png.empty()) out->set_depth_png(f.depth_png);
  v1::FrameStats* s = out->mutable_stats();
  s->set_render_ms(f.stats.render_ms);
  s->set_readback_ms(f.stats.readback_ms);
  s->set_encode_ms(f.stats.encode_ms);
  s->set_latency_ms(f.stats.latency_ms);
  s->set_drops_on_glass(f.stats.drops_on_glass);
  s->set_glass_wet_fraction(f.stats.glass_wet_fraction);
  s->set_view_wet_fraction(f.stats.view_wet_fraction);
  v1::RoadStateFractions* road = s->mutable_road_states();
  road->set_dry(f.stats.road_states[0]);
  road->set_wet(f.stats.road_states[1]);
  road->set_drench(f.stats.road_states[2]);
  road->set_puddle(f.stats.road_states[3]);
  s->set_rain_streaks(f.stats.rain_streaks);
  s->set_background_repeats(f.stats.background_repeats);
  s->set_visibility_m(f.stats.visibility_m);
  s->set_frames_dropped(reader_drops);
  for (const sim::TireWater& t : f.tires) {
    v1::TireWater* tire = out->add_tires();
    tire->set_water_mm(t.water_mm);
    tire->set_standing_mm(t.standing_mm);
    tire->set_state(to_proto(t.state));
  }
  v1::RoadPlace* place = out->mutable_ego_place();
  place->set_road_id(f.ego_place.road);
  place->set_s_m(f.ego_place.s_m);
  place->set_t_m(f.ego_place.t_m);
  place->set_lane_id(f.ego_place.lane);
  place->set_lane_offset_m(f.ego_place.lane_offset_m);
  place->set_on_road(f.ego_place.on_road);
}

void fill_session_info(const session::Session& session, v1::SessionInfo* out) {
  const session::SessionConfig& c = session.config();
  out->set_session_id(session.id());
  out->set_owner(c.owner);
  out->set_mode(c.mode == sim::Mode::kLockstep ? v1::MODE_LOCKSTEP : v1::MODE_REALTIME);
  out->set_fps(c.fps);
  out->set_seed(c.seed);
  out->set_road_network(c.road_network);
  out->set_roads(static_cast<std::uint32_t>(c.roads ? c.roads->road_count() : 1));
  for (const sim::ViewSpec& v : c.views) {
    v1::ViewSpec* spec = out->add_views();
    spec->set_view(to_proto(v.view));
    spec->set_width(static_cast<std::uint32_t>(v.width));
    spec->set_height(static_cast<std::uint32_t>(v.height));
    spec->set_jpeg_quality(static_cast<std::uint32_t>(v.jpeg_quality));
    spec->set_fov_deg(v.fov_deg);
    if (v.camera) {
      spec->mutable_camera_position_m()->set_x(v.camera->position_m.x);
      spec->mutable_camera_position_m()->set_y(v.camera->position_m.y);
      spec->mutable_camera_position_m()->set_z(v.camera->position_m.z);
      spec->mutable_camera_rotation()->set_yaw_deg(v.camera->rotation.yaw_deg);
      spec->mutable_camera_rotation()->set_pitch_deg(v.camera->rotation.pitch_deg);
      spec->mutable_camera_rotation()->set_roll_deg(v.camera->rotation.roll_deg);
    }
    if (v.focus_distance_m) spec->set_focus_distance_m(*v.focus_distance_m);
    if (v.aperture_mm) spec->set_aperture_mm(*v.aperture_mm);
    if (v.exposure_s) spec->set_exposure_s(*v.exposure_s);
    spec->set_background(v.background == sim::Background::kClient ? v1::BACKGROUND_CLIENT
                                                                  : v1::BACKGROUND_RENDERED);
    spec->set_haze(v.haze);
    if (v.outputs.clean) spec->add_outputs(v1::OUTPUT_CLEAN);
    if (v.outputs.water_mask) spec->add_outputs(v1::OUTPUT_WATER_MASK);
    if (v.outputs.depth) spec->add_outputs(v1::OUTPUT_DEPTH);
  }
  out->set_frames_rendered(session.frames_rendered());
  out->set_sim_time_s(session.sim_time_s());
  const session::TickStats ticks = session.tick_stats();
  out->set_frames_late(ticks.frames_late);
  out->set_achieved_fps(ticks.achieved_fps);
  out->set_idle_s(session.idle_s(session::Clock::now()));
  out->set_steps_cancelled(session.steps_cancelled());
}

}  // namespace downpour::rpc
