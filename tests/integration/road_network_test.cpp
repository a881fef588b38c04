// Sessions on roads of their own (the contract's RoadNetwork): a map from the server's --maps-dir
// (a SUMO network converted to OpenDRIVE) and inline OpenDRIVE text; frames that show the road
// under the car and the fields beside it; bad files, bad names and missing maps refused with
// clear statuses while the server keeps serving.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <turbojpeg.h>

#include "downpour/v1/downpour.grpc.pb.h"
#include "tests/integration/requests.hpp"
#include "tests/integration/server_process.hpp"

namespace downpour::testing {
namespace {

using v1::Downpour;

// A car at (x, y) heading `yaw_deg`, at 10 m/s, on a clear afternoon.
v1::Update car_at(double t, double x, double y, double yaw_deg) {
  v1::Update u;
  u.set_sim_time_s(t);
  auto* v = u.mutable_vehicle();
  const double yaw = yaw_deg * 3.14159265358979 / 180.0;
  v->mutable_position_m()->set_x(x + 10.0 * t * std::cos(yaw));
  v->mutable_position_m()->set_y(y + 10.0 * t * std::sin(yaw));
  v->mutable_velocity_mps()->set_x(10.0 * std::cos(yaw));
  v->mutable_velocity_mps()->set_y(10.0 * std::sin(yaw));
  v->mutable_rotation()->set_yaw_deg(yaw_deg);
  auto* w = u.mutable_weather();
  w->set_sun_altitude_deg(45.0);
  w->set_cloudiness(0.2);
  return u;
}

// Of the lower half of a frame (the ground a chase camera sees): the share of asphalt pixels
// (grey, darker than the sky) and of grass (green over red and blue).
struct Ground {
  double asphalt = 0.0;
  double grass = 0.0;
};
Ground ground_of(const std::string& jpeg) {
  if (const char* dir = std::getenv("DOWNPOUR_TEST_FRAMES")) {
    static int n = 0;
    std::FILE* f =
        std::fopen((std::string(dir) + "/frame" + std::to_string(n++) + ".jpg").c_str(), "wb");
    std::fwrite(jpeg.data(), 1, jpeg.size(), f);
    std::fclose(f);
  }
  tjhandle h = tjInitDecompress();
  int w = 0, ht = 0, subsamp = 0, colorspace = 0;
  const auto* data = reinterpret_cast<const unsigned char*>(jpeg.data());
  Ground g;
  if (tjDecompressHeader3(h, data, jpeg.size(), &w, &ht, &subsamp, &colorspace) == 0) {
    std::vector<unsigned char> rgb(static_cast<std::size_t>(w) * ht * 3);
    if (tjDecompress2(h, data, jpeg.size(), rgb.data(), w, 0, ht, TJPF_RGB, 0) == 0) {
      int asphalt = 0, grass = 0, n = 0;
      for (int y = ht / 2; y < ht; ++y) {
        for (int x = 0; x < w; ++x, ++n) {
          const unsigned char* p = &rgb[(static_cast<std::size_t>(y) * w + x) * 3];
          const int r = p[0], gr = p[1], b = p[2];
          if (std::abs(r - gr) < 14 && std::abs(gr - b) < 14 && gr < 150) ++asphalt;
          if (gr > r + 8 && gr > b + 8) ++grass;
        }
      }
      g.asphalt = static_cast<double>(asphalt) / n;
      g.grass = static_cast<double>(grass) / n;
    }
  }
  tjDestroy(h);
  return g;
}

class RoadNetworkTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    server = new ServerProcess({"--maps-dir", DOWNPOUR_TEST_MAPS_DIR, "--max-message-mb", "2",
                                "--max-sessions", "4", "--max-road-km", "5"});
  }
  static void TearDownTestSuite() {
    EXPECT_EQ(server->stop(15.0), 0);
    delete server;
  }
  static ServerProcess* server;
  std::unique_ptr<Downpour::Stub> stub = Downpour::NewStub(server->channel());

  grpc::Status create(const v1::RoadNetwork& roads, const v1::Update& initial,
                      v1::SessionInfo* info) {
    v1::CreateSessionRequest req;
    *req.add_views() = view(v1::VIEW_ROAD, 160, 90);
    req.set_mode(v1::MODE_LOCKSTEP);
    req.set_seed(3);
    *req.mutable_roads() = roads;
    *req.mutable_initial() = initial;
    grpc::ClientContext ctx;
    return stub->CreateSession(&ctx, req, info);
  }
  // Three steps of 0.1 s; the last step's frame.
  std::string drive(const std::string& id, double x, double y, double yaw_deg) {
    v1::StepResponse resp;
    for (int i = 1; i <= 3; ++i) {
      grpc::ClientContext ctx;
      ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
      v1::StepRequest req;
      req.set_session_id(id);
      *req.mutable_update() = car_at(0.1 * i, x, y, yaw_deg);
      req.set_dt_s(0.1);
      const grpc::Status s = stub->Step(&ctx, req, &resp);
      EXPECT_TRUE(s.ok()) << s.error_message();
      if (!s.ok() || resp.frames_size() != 1) return {};
      EXPECT_NEAR(resp.frames(0).sim_time_s(), 0.1 * i, 1e-9);
    }
    return resp.frames(0).jpeg();
  }
  void close(const std::string& id) { EXPECT_TRUE(close_session(*stub, id)); }
};
ServerProcess* RoadNetworkTest::server = nullptr;

v1::RoadNetwork map(const std::string& name) {
  v1::RoadNetwork r;
  r.set_map_name(name);
  return r;
}

TEST_F(RoadNetworkTest, AMapsRoadsAreUnderTheCarAndFieldsBesideThem) {
  // On the grid's western street, northbound in its inner lane (lane -1: 1.6 m right of the
  // centre line), and then in the middle of a block, 75 m from every street.
  v1::SessionInfo on_road, in_field;
  ASSERT_TRUE(create(map("sumo_grid"), car_at(0.0, 1.6, 40.0, 90.0), &on_road).ok());
  EXPECT_EQ(on_road.road_network(), "map:sumo_grid");
  EXPECT_EQ(on_road.roads(), 68u);
  const grpc::Status s = create(map("sumo_grid.xodr"), car_at(0.0, 75.0, 60.0, 90.0), &in_field);
  ASSERT_TRUE(s.ok()) << s.error_message();
  const Ground road = ground_of(drive(on_road.session_id(), 1.6, 40.0, 90.0));
  const Ground field = ground_of(drive(in_field.session_id(), 75.0, 60.0, 90.0));
  std::printf("on the street: asphalt %.2f grass %.2f; in a block: asphalt %.2f grass %.2f\n",
              road.asphalt, road.grass, field.asphalt, field.grass);
  EXPECT_GT(road.asphalt, 0.4);
  EXPECT_LT(field.asphalt, 0.1);
  EXPECT_GT(field.grass, 0.25);
  close(on_road.session_id());
  close(in_field.session_id());
}

TEST_F(RoadNetworkTest, InlineOpenDriveIsParsedAndBadInputIsRefusedClearly) {
  const std::string road = R"(<?xml version="1.0"?>
<OpenDRIVE><header revMajor="1" revMinor="6"/>
  <road id="a" length="200" junction="-1">
    <planView><geometry s="0" x="0" y="0" hdg="0" length="200"><line/></geometry></planView>
    <lanes><laneSection s="0">
      <center><lane id="0" type="none"/></center>
      <right><lane id="-1" type="driving"><width sOffset="0" a="3.5" b="0" c="0" d="0"/></lane>
      </right>
    </laneSection></lanes>
  </road>
</OpenDRIVE>)";
  v1::RoadNetwork inline_roads;
  inline_roads.set_opendrive_xml(road);
  v1::SessionInfo info;
  ASSERT_TRUE(create(inline_roads, car_at(0.0, 10.0, -1.75, 0.0), &info).ok());
  EXPECT_EQ(info.road_network(), "inline");
  EXPECT_EQ(info.roads(), 1u);
  EXPECT_GT(ground_of(drive(info.session_id(), 10.0, -1.75, 0.0)).asphalt, 0.2);
  close(info.session_id());

  auto refused = [&](const v1::RoadNetwork& roads, grpc::StatusCode code, const std::string& says) {
    v1::SessionInfo none;
    const grpc::Status s = create(roads, car_at(0.0, 0.0, 0.0, 0.0), &none);
    EXPECT_EQ(s.error_code(), code) << s.error_message();
    EXPECT_NE(s.error_message().find(says), std::string::npos) << s.error_message();
  };
  // A broken file: the element and its line.
  v1::RoadNetwork broken;
  broken.set_opendrive_xml(R"(<OpenDRIVE>
  <road id="a" length="-3" junction="-1"/>
</OpenDRIVE>)");
  refused(broken, grpc::StatusCode::INVALID_ARGUMENT, "roads.opendrive_xml: <road> line 2");
  v1::RoadNetwork not_xml;
  not_xml.set_opendrive_xml("this is not XML");
  refused(not_xml, grpc::StatusCode::INVALID_ARGUMENT, "roads.opendrive_xml");
  // Names that would be paths, and a map that is not there.
  for (const std::string name : {"../sumo_grid.xodr", "/etc/passwd", ".hidden", "a/b", ""}) {
    refused(map(name), grpc::StatusCode::INVALID_ARGUMENT, "roads.map_name");
  }
  refused(map("atlantis"), grpc::StatusCode::NOT_FOUND, "no map \"atlantis\"");
  // More road than the server builds a scene for (5 km here).
  std::string long_roads = "<OpenDRIVE><header revMajor=\"1\" revMinor=\"6\"/>";
  for (const char* id : {"a", "b"}) {
    long_roads += std::string("<road id=\"") + id + R"(" length="3000" junction="-1">
      <planView><geometry s="0" x="0" y="0" hdg="0" length="3000"><line/></geometry></planView>
      <lanes><laneSection s="0"><center><lane id="0" type="none"/></center></laneSection></lanes>
    </road>)";
  }
  v1::RoadNetwork too_long;
  too_long.set_opendrive_xml(long_roads + "</OpenDRIVE>");
  refused(too_long, grpc::StatusCode::INVALID_ARGUMENT, "add up to more than 5000");
  // Past the message limit (2 MiB here): refused naming the flag that raises it; and far past it,
  // gRPC's own refusal.
  v1::RoadNetwork huge;
  huge.set_opendrive_xml(std::string(3 << 20, ' '));
  refused(huge, grpc::StatusCode::RESOURCE_EXHAUSTED, "--max-message-mb");
  v1::RoadNetwork far_past;
  far_past.set_opendrive_xml(std::string(20 << 20, ' '));
  refused(far_past, grpc::StatusCode::RESOURCE_EXHAUSTED, "");
  // The server still serves.
  ASSERT_TRUE(create(map("sumo_grid"), car_at(0.0, 1.6, 40.0, 90.0), &info).ok());
  close(info.session_id());
}

}  // namespace
}  // namespace downpour::testing
