// A simulator's side of a lockstep session, through the C++ client library: ten steps of a car
// driving down the built-in track's outer lane in rain, each step's frames written as JPEG files.
//   downpour-client-example [SERVER [OUT_DIR]]   (default 127.0.0.1:50051, .)
#include <cstdio>
#include <fstream>
#include <string>

#include <downpour/client.hpp>

int main(int argc, char** argv) {
  namespace v1 = downpour::v1;
  const std::string target = argc > 1 ? argv[1] : "127.0.0.1:50051";
  const std::string out = argc > 2 ? argv[2] : ".";
  try {
    downpour::client::Client client({target});
    v1::CreateSessionRequest request;
    for (const v1::View view : {v1::VIEW_COCKPIT, v1::VIEW_ROAD}) {
      v1::ViewSpec* spec = request.add_views();
      spec->set_view(view);
      spec->set_width(320);
      spec->set_height(180);
    }
    request.set_seed(42);
    downpour::client::LockstepSession session(client, request);
    std::printf("session %s on %s\n", session.info().session_id().c_str(),
                session.info().road_network().c_str());
    int written = 0;
    for (int step = 1; step <= 10; ++step) {
      v1::Update update;
      update.set_sim_time_s(0.05 * step);
      v1::VehicleState* car = update.mutable_vehicle();
      car->mutable_position_m()->set_x(25.0 * 0.05 * step);
      car->mutable_position_m()->set_y(-5.25);  // the outer lane
      car->mutable_velocity_mps()->set_x(25.0);
      update.mutable_weather()->set_rain_rate_mm_h(15.0);
      update.mutable_wipers()->set_mode(v1::WIPER_LOW);
      for (const v1::Frame& frame : session.step(0.05, update)) {
        const std::string path = out + "/" + std::to_string(frame.frame_number()) + "_" +
                                 v1::View_Name(frame.view()) + ".jpg";
        std::ofstream(path, std::ios::binary) << frame.jpeg();
        ++written;
      }
    }
    std::printf("%d frames written to %s\n", written, out.c_str());
  } catch (const downpour::client::Error& e) {
    std::fprintf(stderr, "downpour: %s (status %d)\n", e.what(), static_cast<int>(e.code()));
    return 1;
  }
  return 0;
}
