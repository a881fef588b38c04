// Models a session names (the contract's EgoVehicle.body_model and cabin_model,
// TrafficVehicle.model) from the server's --models-dir: a session drives with its own car, cabin
// and traffic models; a model that is missing, broken, too large or badly named, a cabin whose
// windshield disagrees with the glass asked for, and a server without models are all refused with
// a clear status, and the session goes on as it was.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "downpour/v1/downpour.grpc.pb.h"
#include "server/model/default_models.hpp"
#include "server/model/gltf_model.hpp"
#include "tests/integration/requests.hpp"
#include "tests/integration/server_process.hpp"

namespace downpour::testing {
namespace {

using v1::Downpour;

class ModelsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir = new std::string(::testing::TempDir() + "downpour_models_test");
    std::filesystem::create_directories(*dir);
    auto write = [](const std::string& name, const std::string& bytes) {
      std::ofstream(*dir + "/" + name, std::ios::binary) << bytes;
    };
    write("hatch.glb",
          model::write_glb(model::default_vehicle(sim::VehicleClass::kCar, model::Detail::kFar)));
    write("lorry.glb", model::write_glb(model::default_vehicle(sim::VehicleClass::kTruck)));
    write("cockpit.glb", model::write_glb(model::default_cabin(sim::GlassConfig{})));
    sim::GlassConfig steep;
    steep.rake_deg = 45.0;
    write("steep_cockpit.glb", model::write_glb(model::default_cabin(steep)));
    write("broken.glb", "glTF but not really");
    server = new ServerProcess(
        {"--models-dir", *dir, "--model-max-triangles", "4000", "--max-sessions", "4"});
  }
  static void TearDownTestSuite() {
    EXPECT_EQ(server->stop(15.0), 0);
    delete server;
    delete dir;
  }
  static ServerProcess* server;
  static std::string* dir;
  std::unique_ptr<Downpour::Stub> stub = Downpour::NewStub(server->channel());

  static v1::CreateSessionRequest request(const std::string& body, const std::string& cabin) {
    v1::CreateSessionRequest req;
    *req.add_views() = view(v1::VIEW_COCKPIT, 160, 90);
    *req.add_views() = view(v1::VIEW_ROAD, 160, 90);
    req.set_mode(v1::MODE_LOCKSTEP);
    req.set_seed(5);
    *req.mutable_initial() = drive_update(0.0);
    req.mutable_ego()->set_body_model(body);
    req.mutable_ego()->set_cabin_model(cabin);
    return req;
  }
  grpc::Status create(const v1::CreateSessionRequest& req, v1::SessionInfo* info) {
    grpc::ClientContext ctx;
    return stub->CreateSession(&ctx, req, info);
  }
  // A step with a vehicle ahead in the given model.
  grpc::Status step(const std::string& id, double t, const std::string& traffic_model) {
    v1::StepRequest req;
    req.set_session_id(id);
    req.set_dt_s(0.1);
    *req.mutable_update() = drive_update(t);
    v1::TrafficVehicle* v = req.mutable_update()->add_traffic();
    v->set_id(7);
    v->mutable_state()->mutable_position_m()->set_x(20.0 * t + 18.0);
    v->mutable_state()->mutable_position_m()->set_y(-5.25);
    v->mutable_state()->mutable_velocity_mps()->set_x(20.0);
    v->set_model(traffic_model);
    req.mutable_update()->set_replace_traffic(true);
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
    v1::StepResponse resp;
    const grpc::Status s = stub->Step(&ctx, req, &resp);
    if (s.ok()) {
      EXPECT_EQ(resp.frames_size(), 2);
    }
    return s;
  }
};

ServerProcess* ModelsTest::server = nullptr;
std::string* ModelsTest::dir = nullptr;

TEST_F(ModelsTest, ASessionDrivesWithItsOwnCarCabinAndTraffic) {
  v1::SessionInfo info;
  const grpc::Status created = create(request("hatch", "cockpit"), &info);
  ASSERT_TRUE(created.ok()) << created.error_message();
  for (int i = 1; i <= 3; ++i) {
    const grpc::Status s = step(info.session_id(), 0.1 * i, i == 2 ? "hatch.glb" : "hatch");
    EXPECT_TRUE(s.ok()) << s.error_message();
  }
  // A cabin whose windshield is not the default car's gives the session its glass.
  v1::SessionInfo steep;
  const grpc::Status s = create(request("", "steep_cockpit"), &steep);
  EXPECT_TRUE(s.ok()) << s.error_message();
  EXPECT_TRUE(step(steep.session_id(), 0.1, "").ok());
  close_session(*stub, info.session_id());
  close_session(*stub, steep.session_id());
}

TEST_F(ModelsTest, BadModelsAreRefusedAndTheSessionGoesOn) {
  v1::SessionInfo info;
  ASSERT_TRUE(create(request("", ""), &info).ok());
  struct Case {
    const char* model;
    grpc::StatusCode code;
    const char* says;
  };
  for (const Case& c :
       {Case{"nowhere", grpc::StatusCode::NOT_FOUND, "no model"},
        Case{"broken", grpc::StatusCode::INVALID_ARGUMENT, "binary glTF"},
        Case{"../hatch", grpc::StatusCode::INVALID_ARGUMENT, "file name"},
        Case{"lorry", grpc::StatusCode::INVALID_ARGUMENT, "more than 4000 triangles"}}) {
    const grpc::Status s = step(info.session_id(), 0.1, c.model);
    std::printf("traffic model \"%s\": %d %s\n", c.model, s.error_code(),
                s.error_message().c_str());
    EXPECT_EQ(s.error_code(), c.code) << c.model;
    EXPECT_NE(s.error_message().find(c.says), std::string::npos) << s.error_message();
    EXPECT_NE(s.error_message().find("update.traffic[0].model"), std::string::npos);
  }
  EXPECT_TRUE(step(info.session_id(), 0.1, "hatch").ok()) << "the session goes on";
  // A cabin whose windshield disagrees with the one asked for.
  v1::CreateSessionRequest req = request("", "steep_cockpit");
  v1::Windshield* w = req.mutable_ego()->mutable_windshield();
  const sim::GlassConfig glass;
  w->set_bottom_width_mm(glass.bottom_width_mm);
  w->set_top_width_mm(glass.top_width_mm);
  w->set_height_mm(glass.height_mm);
  w->set_rake_deg(glass.rake_deg);
  w->mutable_bottom_left_m()->set_x(glass.bottom_left_m.x);
  w->mutable_bottom_left_m()->set_y(glass.bottom_left_m.y);
  w->mutable_bottom_left_m()->set_z(glass.bottom_left_m.z);
  v1::SessionInfo refused;
  const grpc::Status s = create(req, &refused);
  std::printf("steep cabin on the default glass: %s\n", s.error_message().c_str());
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(s.error_message().find("does not match"), std::string::npos);
  // The same cabin on its own glass is fine.
  w->set_rake_deg(45.0);
  v1::SessionInfo agreed;
  const grpc::Status ok = create(req, &agreed);
  EXPECT_TRUE(ok.ok()) << ok.error_message();
  close_session(*stub, agreed.session_id());
  close_session(*stub, info.session_id());
}

TEST(ModelsWithoutDirectoryTest, AServerWithoutModelsSaysSo) {
  ServerProcess bare({"--max-sessions", "2"});
  auto stub = Downpour::NewStub(bare.channel());
  v1::CreateSessionRequest req;
  *req.add_views() = view(v1::VIEW_ROAD, 160, 90);
  req.mutable_ego()->set_body_model("hatch");
  grpc::ClientContext ctx;
  v1::SessionInfo info;
  const grpc::Status s = stub->CreateSession(&ctx, req, &info);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_NE(s.error_message().find("--models-dir"), std::string::npos) << s.error_message();
  EXPECT_NE(s.error_message().find("ego.body_model"), std::string::npos) << s.error_message();
  EXPECT_EQ(bare.stop(15.0), 0);
}

}  // namespace
}  // namespace downpour::testing
