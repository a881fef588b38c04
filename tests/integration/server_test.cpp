// The real server binary driven by a scripted C++ client: sessions in both modes, decoded JPEGs,
// lockstep determinism, bad input, slow readers, shutdown.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include <gtest/gtest.h>
#include <turbojpeg.h>

#include "downpour/v1/downpour.grpc.pb.h"
#include "grpc_health/v1/health.grpc.pb.h"
#include "tests/integration/server_process.hpp"

namespace downpour::testing {
namespace {

using v1::Downpour;

// One server for the whole file; each test makes its own sessions and closes them.
ServerProcess* g_server = nullptr;

class ServerEnvironment : public ::testing::Environment {
 public:
  void SetUp() override { g_server = new ServerProcess(); }
  void TearDown() override {
    // SIGTERM drains and exits cleanly, promptly.
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_EQ(g_server->stop(15.0), 0);
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
    delete g_server;
  }
};
const auto* const g_env = ::testing::AddGlobalTestEnvironment(new ServerEnvironment);

struct Decoded {
  int width = 0;
  int height = 0;
  bool ok = false;
};

Decoded decode(const std::string& jpeg) {
  tjhandle h = tjInitDecompress();
  Decoded d;
  int subsamp = 0, colorspace = 0;
  const auto* data = reinterpret_cast<const unsigned char*>(jpeg.data());
  if (tjDecompressHeader3(h, data, jpeg.size(), &d.width, &d.height, &subsamp, &colorspace) == 0) {
    std::vector<unsigned char> rgb(static_cast<std::size_t>(d.width) * d.height * 3);
    d.ok = tjDecompress2(h, data, jpeg.size(), rgb.data(), d.width, 0, d.height, TJPF_RGB, 0) == 0;
  }
  tjDestroy(h);
  return d;
}

v1::ViewSpec view(v1::View v, int w, int h) {
  v1::ViewSpec s;
  s.set_view(v);
  s.set_width(w);
  s.set_height(h);
  s.set_jpeg_quality(80);
  return s;
}

// An update that moves the vehicle along +x at 20 m/s in rain.
v1::Update drive_update(double t) {
  v1::Update u;
  u.set_sim_time_s(t);
  auto* v = u.mutable_vehicle();
  v->mutable_position_m()->set_x(20.0 * t);
  v->mutable_position_m()->set_y(-5.25);
  v->mutable_velocity_mps()->set_x(20.0);
  auto* w = u.mutable_weather();
  w->set_rain_rate_mm_h(10.0);
  w->set_cloudiness(0.8);
  w->set_sun_altitude_deg(35.0);
  u.mutable_wipers()->set_mode(v1::WIPER_LOW);
  return u;
}

class ServerTest : public ::testing::Test {
 protected:
  std::unique_ptr<Downpour::Stub> stub = Downpour::NewStub(g_server->channel());

  std::string create(v1::Mode mode, std::vector<v1::ViewSpec> views, std::uint64_t seed = 1,
                     double fps = 0.0) {
    v1::CreateSessionRequest req;
    for (auto& v : views) *req.add_views() = v;
    req.set_mode(mode);
    req.set_seed(seed);
    req.set_fps(fps);
    *req.mutable_initial() = drive_update(0.0);
    v1::SessionInfo info;
    grpc::ClientContext ctx;
    const grpc::Status s = stub->CreateSession(&ctx, req, &info);
    EXPECT_TRUE(s.ok()) << s.error_message();
    return info.session_id();
  }

  void close(const std::string& id) {
    grpc::ClientContext ctx;
    v1::CloseSessionRequest req;
    req.set_session_id(id);
    v1::CloseSessionResponse resp;
    EXPECT_TRUE(stub->CloseSession(&ctx, req, &resp).ok());
  }

  grpc::Status step(const std::string& id, double t, double dt, v1::StepResponse* out) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    v1::StepRequest req;
    req.set_session_id(id);
    *req.mutable_update() = drive_update(t);
    req.set_dt_s(dt);
    return stub->Step(&ctx, req, out);
  }
};

TEST_F(ServerTest, HealthIsServing) {
  auto health = grpc::health::v1::Health::NewStub(g_server->channel());
  grpc::ClientContext ctx;
  grpc::health::v1::HealthCheckRequest req;
  grpc::health::v1::HealthCheckResponse resp;
  ASSERT_TRUE(health->Check(&ctx, req, &resp).ok());
  EXPECT_EQ(resp.status(), grpc::health::v1::HealthCheckResponse::SERVING);
}

TEST_F(ServerTest, LockstepStepReturnsDecodableFramesInOrder) {
  const std::string id =
      create(v1::MODE_LOCKSTEP, {view(v1::VIEW_COCKPIT, 160, 90), view(v1::VIEW_ROAD, 128, 72)});
  for (int i = 1; i <= 4; ++i) {
    v1::StepResponse resp;
    const grpc::Status s = step(id, i * 0.05, 0.05, &resp);
    ASSERT_TRUE(s.ok()) << s.error_message();
    ASSERT_EQ(resp.frames_size(), 2);
    EXPECT_EQ(resp.frames(0).view(), v1::VIEW_COCKPIT);
    EXPECT_EQ(resp.frames(1).view(), v1::VIEW_ROAD);
    for (const auto& f : resp.frames()) {
      EXPECT_EQ(f.frame_number(), static_cast<std::uint64_t>(i));
      EXPECT_NEAR(f.sim_time_s(), i * 0.05, 1e-9);
      EXPECT_NEAR(f.client_time_s(), i * 0.05, 1e-9);
      const Decoded d = decode(f.jpeg());
      EXPECT_TRUE(d.ok);
      EXPECT_EQ(d.width, static_cast<int>(f.width()));
      EXPECT_EQ(d.height, static_cast<int>(f.height()));
    }
    EXPECT_EQ(decode(resp.frames(0).jpeg()).width, 160);
    EXPECT_EQ(decode(resp.frames(1).jpeg()).height, 72);
  }
  close(id);
}

TEST_F(ServerTest, LockstepIsDeterministicForTheSameSeedAndInputs) {
  auto run = [&](std::uint64_t seed, double offset) {
    const std::string id = create(v1::MODE_LOCKSTEP, {view(v1::VIEW_COCKPIT, 160, 90)}, seed);
    std::vector<std::string> jpegs;
    for (int i = 1; i <= 3; ++i) {
      v1::StepResponse resp;
      EXPECT_TRUE(step(id, i * 0.1 + offset, 0.1, &resp).ok());
      jpegs.push_back(resp.frames(0).jpeg());
    }
    close(id);
    return jpegs;
  };
  const auto a = run(42, 0.0);
  const auto b = run(42, 0.0);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a, b);
  const auto moved = run(42, 1.0);  // other inputs: the vehicle 20 m further on
  EXPECT_NE(a, moved);
}

TEST_F(ServerTest, DriveLockstepAnswersEachStepOnceInOrder) {
  const std::string id = create(v1::MODE_LOCKSTEP, {view(v1::VIEW_COCKPIT, 96, 54)});
  grpc::ClientContext ctx;
  auto stream = stub->Drive(&ctx);
  const int steps = 8;
  std::thread writer([&] {
    for (int i = 0; i < steps; ++i) {
      v1::DriveRequest req;
      if (i == 0) req.set_session_id(id);
      *req.mutable_update() = drive_update(i * 0.1);
      req.set_dt_s(0.1);
      stream->Write(req);
      if (i == 3) {  // an update-only request: no response of its own
        v1::DriveRequest only;
        *only.mutable_update() = drive_update(i * 0.1 + 0.05);
        stream->Write(only);
      }
    }
    stream->WritesDone();
  });
  std::vector<std::uint64_t> numbers;
  v1::DriveResponse resp;
  while (stream->Read(&resp)) {
    ASSERT_EQ(resp.frames_size(), 1);
    numbers.push_back(resp.frames(0).frame_number());
    EXPECT_NEAR(resp.frames(0).sim_time_s(), numbers.size() * 0.1, 1e-9);
  }
  writer.join();
  EXPECT_TRUE(stream->Finish().ok());
  std::vector<std::uint64_t> expected(steps);
  for (int i = 0; i < steps; ++i) expected[i] = i + 1;
  EXPECT_EQ(numbers, expected);
  close(id);
}

TEST_F(ServerTest, RealtimeSessionStreamsToWatchers) {
  const std::string id = create(v1::MODE_REALTIME, {view(v1::VIEW_ROAD, 128, 72)}, 3, 20.0);
  grpc::ClientContext ctx;
  v1::WatchFramesRequest req;
  req.set_session_id(id);
  auto reader = stub->WatchFrames(&ctx, req);
  v1::Frame frame;
  std::uint64_t last = 0;
  int count = 0;
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(1500);
  while (std::chrono::steady_clock::now() < until && reader->Read(&frame)) {
    EXPECT_GT(frame.frame_number(), last);
    last = frame.frame_number();
    EXPECT_EQ(decode(frame.jpeg()).width, 128);
    ++count;
  }
  EXPECT_GE(count, 5);
  close(id);  // ends the stream with OK
  while (reader->Read(&frame)) {
  }
  EXPECT_TRUE(reader->Finish().ok());
}

TEST_F(ServerTest, BadInputGetsAClearStatusAndTheServerKeepsServing) {
  struct Case {
    const char* name;
    std::function<void(v1::CreateSessionRequest&)> mutate;
    const char* field;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Case> cases = {
      {"rain over 500",
       [](auto& r) { r.mutable_initial()->mutable_weather()->set_rain_rate_mm_h(600); },
       "rain_rate_mm_h"},
      {"negative rain",
       [](auto& r) { r.mutable_initial()->mutable_weather()->set_rain_rate_mm_h(-1); },
       "rain_rate_mm_h"},
      {"NaN position",
       [nan](auto& r) { r.mutable_initial()->mutable_vehicle()->mutable_position_m()->set_x(nan); },
       "position_m.x"},
      {"infinite speed",
       [](auto& r) {
         r.mutable_initial()->mutable_vehicle()->mutable_velocity_mps()->set_y(
             std::numeric_limits<double>::infinity());
       },
       "velocity_mps.y"},
      {"width 0", [](auto& r) { r.mutable_views(0)->set_width(0); }, "views[0].width"},
      {"width over the limit", [](auto& r) { r.mutable_views(0)->set_width(100000); },
       "views[0].width"},
      {"quality 101", [](auto& r) { r.mutable_views(0)->set_jpeg_quality(101); }, "jpeg_quality"},
      {"unknown view", [](auto& r) { r.mutable_views(0)->set_view(static_cast<v1::View>(42)); },
       "views[0].view"},
      {"unknown mode", [](auto& r) { r.set_mode(static_cast<v1::Mode>(9)); }, "mode"},
      {"unknown wiper mode",
       [](auto& r) {
         r.mutable_initial()->mutable_wipers()->set_mode(static_cast<v1::WiperMode>(77));
       },
       "wipers.mode"},
      {"no views", [](auto& r) { r.clear_views(); }, "views"},
  };
  for (const Case& c : cases) {
    v1::CreateSessionRequest req;
    *req.add_views() = view(v1::VIEW_COCKPIT, 64, 36);
    req.set_mode(v1::MODE_LOCKSTEP);
    c.mutate(req);
    grpc::ClientContext ctx;
    v1::SessionInfo info;
    const grpc::Status s = stub->CreateSession(&ctx, req, &info);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << c.name;
    EXPECT_NE(s.error_message().find(c.field), std::string::npos)
        << c.name << ": " << s.error_message();
  }
  // Unknown session, bad dt, Step on a realtime session.
  v1::StepResponse resp;
  EXPECT_EQ(step("s999-nope", 0.0, 0.1, &resp).error_code(), grpc::StatusCode::NOT_FOUND);
  const std::string id = create(v1::MODE_LOCKSTEP, {view(v1::VIEW_COCKPIT, 64, 36)});
  EXPECT_EQ(step(id, 0.0, -1.0, &resp).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(step(id, 0.0, nan, &resp).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(step(id, 0.0, 0.0, &resp).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  const std::string rt = create(v1::MODE_REALTIME, {view(v1::VIEW_COCKPIT, 64, 36)});
  EXPECT_EQ(step(rt, 0.0, 0.1, &resp).error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  close(rt);
  // Still serving: the good session steps.
  v1::StepResponse ok;
  EXPECT_TRUE(step(id, 0.1, 0.1, &ok).ok());
  EXPECT_EQ(ok.frames_size(), 1);
  close(id);
}

TEST_F(ServerTest, SessionLimitGivesResourceExhausted) {
  std::vector<std::string> ids;
  grpc::Status last;
  for (int i = 0; i < 12; ++i) {
    v1::CreateSessionRequest req;
    *req.add_views() = view(v1::VIEW_RAIN, 16, 16);
    req.set_mode(v1::MODE_LOCKSTEP);
    grpc::ClientContext ctx;
    v1::SessionInfo info;
    last = stub->CreateSession(&ctx, req, &info);
    if (!last.ok()) break;
    ids.push_back(info.session_id());
  }
  EXPECT_EQ(last.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_EQ(ids.size(), 8u);  // the default limit
  for (const auto& id : ids) close(id);
}

TEST_F(ServerTest, StalledReaderNeitherGrowsMemoryNorSlowsAnotherSession) {
  // A realtime session at 30 fps, 640 x 360, whose one reader never reads.
  const std::string rt = create(v1::MODE_REALTIME, {view(v1::VIEW_COCKPIT, 640, 360)}, 5, 30.0);
  const std::string ls = create(v1::MODE_LOCKSTEP, {view(v1::VIEW_ROAD, 160, 90)});
  auto time_steps = [&](int n) {
    std::vector<double> ms;
    for (int i = 0; i < n; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      v1::StepResponse resp;
      EXPECT_TRUE(step(ls, i * 0.05, 0.05, &resp).ok());
      ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    std::nth_element(ms.begin(), ms.begin() + n / 2, ms.end());
    return ms[n / 2];
  };
  v1::WatchFramesRequest req;
  req.set_session_id(rt);
  // The baseline: the realtime session has a reader that keeps up, so that it renders and encodes
  // as much as it will with the stalled one: only the stall differs between the two timings.
  double baseline = 0.0;
  {
    grpc::ClientContext reading_ctx;
    auto reading = stub->WatchFrames(&reading_ctx, req);
    std::thread reader([&] {
      v1::Frame frame;
      while (reading->Read(&frame)) {
      }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    baseline = time_steps(15);
    reading_ctx.TryCancel();
    reader.join();
    reading->Finish();
  }

  // A reader on its own connection with a small, fixed flow-control window (no BDP growth), so
  // that it stops accepting data after a few frames, like a stuck client.
  grpc::ChannelArguments args;
  args.SetInt(GRPC_ARG_HTTP2_BDP_PROBE, 0);
  args.SetInt(GRPC_ARG_HTTP2_STREAM_LOOKAHEAD_BYTES, 64 * 1024);
  args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  auto stalled_stub = Downpour::NewStub(
      grpc::CreateCustomChannel(g_server->target(), grpc::InsecureChannelCredentials(), args));
  grpc::ClientContext stalled_ctx;
  auto stalled = stalled_stub->WatchFrames(&stalled_ctx, req);  // never Read()
  std::this_thread::sleep_for(std::chrono::seconds(2));         // flow-control windows fill up
  const long rss_before = g_server->rss_kib();
  const double with_stall = time_steps(15);
  std::this_thread::sleep_for(std::chrono::seconds(3));
  const long rss_after = g_server->rss_kib();

  // Bounded: a latest-frame slot holds one frame; 3 s more at 30 fps must not pile up frames.
  EXPECT_LT(rss_after - rss_before, 16 * 1024)
      << "RSS grew from " << rss_before << " to " << rss_after << " KiB";
  // Another session's steps are not held up by the stalled reader more than by a reader that
  // keeps up (generous: a 2-core machine).
  EXPECT_LT(with_stall, baseline * 2.0 + 20.0)
      << "median step " << baseline << " ms -> " << with_stall << " ms";
  grpc::ClientContext stats_ctx;
  v1::ServerStats stats;
  ASSERT_TRUE(stub->GetStats(&stats_ctx, v1::GetStatsRequest(), &stats).ok());
  EXPECT_GT(stats.frames_dropped(), 0u);  // the stalled reader's frames were dropped, not queued

  stalled_ctx.TryCancel();
  close(rt);
  close(ls);
}

}  // namespace
}  // namespace downpour::testing
