// The C++ client library follows a session to the server that holds it (SessionInfo.endpoint,
// the server's --advertise), as it would across the replicas of a headless Service.
#include <string>

#include <gtest/gtest.h>

#include "downpour/client.hpp"
#include "tests/integration/server_process.hpp"

namespace downpour::testing {
namespace {

v1::CreateSessionRequest small_request() {
  v1::CreateSessionRequest request;
  v1::ViewSpec* view = request.add_views();
  view->set_view(v1::VIEW_ROAD);
  view->set_width(64);
  view->set_height(36);
  return request;
}

TEST(ClientRoutingTest, ASessionsCallsGoToTheEndpointItsServerAdvertises) {
  const std::string a_address = "127.0.0.1:" + std::to_string(free_port());
  // With metrics on, so that the sanitizer runs see their observer and interceptor at work.
  ServerProcess a(
      {"--listen", a_address, "--advertise", a_address, "--metrics-listen", "127.0.0.1:0"});
  // B says that its sessions live on A, as a misconfigured replica would: the client follows.
  ServerProcess b({"--advertise", a_address});

  // Dialled by another name, A's sessions are reached at the address A advertises.
  client::Client through_a_name({"localhost:" + a_address.substr(a_address.find(':') + 1)});
  {
    client::LockstepSession session(through_a_name, small_request());
    EXPECT_EQ(session.info().endpoint(), a_address);
    for (int i = 0; i < 3; ++i) {
      const auto frames = session.step(0.05);
      ASSERT_EQ(frames.size(), 1u);
      EXPECT_EQ(frames[0].frame_number(), static_cast<std::uint64_t>(i + 1));
    }
  }
  EXPECT_TRUE(through_a_name.list_sessions().empty());  // closed where it lived

  // Created on B, followed to A, which does not hold it: the calls went to the endpoint.
  client::Client client_of_b({b.target()});
  client::LockstepSession elsewhere(client_of_b, small_request());
  EXPECT_EQ(elsewhere.info().endpoint(), a_address);
  try {
    elsewhere.step(0.05);
    FAIL() << "the step reached B";
  } catch (const client::Error& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::NOT_FOUND) << e.what();
  }
  EXPECT_EQ(client_of_b.list_sessions().size(), 1u);  // B still holds it
}

}  // namespace
}  // namespace downpour::testing
