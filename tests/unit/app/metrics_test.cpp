#include "server/app/metrics.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <string>

#include <gtest/gtest.h>

#include "server/rpc/call_status.hpp"

namespace downpour::app {
namespace {

// GET path over plain HTTP from 127.0.0.1:port; the whole answer, headers included.
std::string http_get(int port, const std::string& path) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    close(fd);
    return {};
  }
  const std::string request = "GET " + path + " HTTP/1.0\r\nHost: localhost\r\n\r\n";
  if (write(fd, request.data(), request.size()) != static_cast<ssize_t>(request.size())) {
    close(fd);
    return {};
  }
  std::string answer;
  char buffer[4096];
  for (ssize_t n; (n = read(fd, buffer, sizeof buffer)) > 0;) answer.append(buffer, n);
  close(fd);
  return answer;
}

TEST(MetricsTest, ServesFramesSessionsAndErrorsOnItsPort) {
  Metrics metrics("127.0.0.1:0");
  ASSERT_GT(metrics.port(), 0);
  metrics.set_build_info("1.2.3", "llvmpipe");
  metrics.rendered(12.0);
  metrics.rendered(30.0);
  metrics.encoded(3.0, 45.0);
  metrics.call_finished("CreateSession", grpc::StatusCode::OK);
  metrics.call_finished("Step", grpc::StatusCode::NOT_FOUND);
  metrics.call_finished("Step", grpc::StatusCode::NOT_FOUND);
  MetricsSample sample;
  sample.frames_dropped = 7;
  sample.frames_late = 3;
  sample.sessions_lockstep = 1;
  sample.sessions_realtime = 2;
  sample.serving = true;
  metrics.update(sample);
  sample.frames_late = 5;
  metrics.update(sample);

  const std::string page = http_get(metrics.port(), "/metrics");
  ASSERT_NE(page.find("200 OK"), std::string::npos) << page;
  for (const char* line : {
           R"(downpour_frames_total{stage="rendered"} 2)",
           R"(downpour_frames_total{stage="encoded"} 1)",
           R"(downpour_frames_total{stage="dropped"} 7)",
           "downpour_frames_late_total 5",
           R"(downpour_sessions{mode="lockstep"} 1)",
           R"(downpour_sessions{mode="realtime"} 2)",
           R"(downpour_rpc_errors_total{code="NOT_FOUND",method="Step"} 2)",
           R"(downpour_rpc_calls_total{code="OK",method="CreateSession"} 1)",
           "downpour_render_seconds_count 2",
           R"(downpour_render_seconds_bucket{le="0.02"} 1)",
           "downpour_frame_latency_seconds_sum 0.045",
           R"(downpour_build_info{renderer="llvmpipe",version="1.2.3"} 1)",
           "downpour_serving 1",
       }) {
    EXPECT_NE(page.find(line), std::string::npos) << "missing: " << line << "\n" << page;
  }
  EXPECT_EQ(page.find("downpour_rpc_errors_total{code=\"OK\""), std::string::npos);
}

TEST(MetricsTest, APortInUseIsRefusedWithItsAddress) {
  Metrics first("127.0.0.1:0");
  const std::string taken = "127.0.0.1:" + std::to_string(first.port());
  try {
    Metrics second(taken);
    FAIL() << "a second server listened on " << taken;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(taken), std::string::npos) << e.what();
  }
}

TEST(MetricsTest, StatusCodesAndMethodsHaveBoundedNames) {
  EXPECT_EQ(status_code_name(grpc::StatusCode::OK), "OK");
  EXPECT_EQ(status_code_name(grpc::StatusCode::RESOURCE_EXHAUSTED), "RESOURCE_EXHAUSTED");
  EXPECT_EQ(status_code_name(grpc::StatusCode::UNAUTHENTICATED), "UNAUTHENTICATED");
  EXPECT_EQ(status_code_name(static_cast<grpc::StatusCode>(99)), "UNKNOWN");
  EXPECT_EQ(rpc::method_label("/downpour.v1.Downpour/Step"), "Step");
  EXPECT_EQ(rpc::method_label("/grpc.health.v1.Health/Check"), "Check");
  // A client may send any path: none of them makes a new label.
  EXPECT_EQ(rpc::method_label("/downpour.v1.Downpour/Nope"), "other");
  EXPECT_EQ(rpc::method_label("/evil.Service/Step"), "other");
  EXPECT_EQ(rpc::method_label(""), "other");
}

}  // namespace
}  // namespace downpour::app
