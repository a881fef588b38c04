// Starts the real server binary (DOWNPOUR_SERVER) on a free port for a test, stops it with
// SIGTERM and reports how it exited.
#pragma once

#include <sys/types.h>

#include <memory>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>

namespace downpour::testing {

// How much slower than a normal build the server under test may be (DOWNPOUR_TEST_TIME_SCALE;
// the sanitizer runs set it), for the tests' bounds on wall time.
double time_scale();

// A loopback port the kernel just handed out and took back (for a flag that needs one ahead).
int free_port();

class ServerProcess {
 public:
  // With the minimal warm-up unless extra_args name --warm-up.
  explicit ServerProcess(std::vector<std::string> extra_args = {});
  ~ServerProcess();

  const std::string& target() const { return target_; }
  std::shared_ptr<grpc::Channel> channel() const { return channel_; }
  pid_t pid() const { return pid_; }
  // Resident memory of the server process in KiB (from /proc).
  long rss_kib() const;
  // SIGTERM, then wait up to timeout_s; returns the exit status, or -1 if it had to be killed.
  int stop(double timeout_s = 15.0);
  void signal(int number) const;
  // Waits up to timeout_s for the process to exit (then kills it); as stop().
  int wait(double timeout_s);

 private:
  pid_t pid_ = -1;
  std::string dir_;
  std::string target_;
  std::shared_ptr<grpc::Channel> channel_;
};

}  // namespace downpour::testing
