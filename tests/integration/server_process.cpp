#include "tests/integration/server_process.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace downpour::testing {

double time_scale() {
  const char* scale = std::getenv("DOWNPOUR_TEST_TIME_SCALE");
  return scale ? std::max(1.0, std::atof(scale)) : 1.0;
}

int free_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  socklen_t len = sizeof addr;
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  close(fd);
  return ntohs(addr.sin_port);
}

ServerProcess::ServerProcess(std::vector<std::string> extra_args) {
  const char* binary = std::getenv("DOWNPOUR_SERVER");
  if (!binary) throw std::runtime_error("DOWNPOUR_SERVER is not set");
  char tmpl[] = "/tmp/downpour-test-XXXXXX";
  if (!mkdtemp(tmpl)) throw std::runtime_error("mkdtemp failed");
  dir_ = tmpl;
  const std::string port_file = dir_ + "/port";
  std::vector<std::string> args = {binary, "--port-file", port_file, "--log-level", "warn"};
  // A free port on loopback, unless the test listens elsewhere.
  if (std::find(extra_args.begin(), extra_args.end(), "--listen") == extra_args.end()) {
    args.push_back("--listen");
    args.push_back("127.0.0.1:0");
  }
  // The smallest warm-up, unless the test asks (warm_up.hpp): the full one takes 2 s a start
  // (5-6 under ASan), and only the streams of a test that times them mind a shader compiled in
  // their first ticks.
  if (std::find(extra_args.begin(), extra_args.end(), "--warm-up") == extra_args.end()) {
    args.push_back("--warm-up");
    args.push_back("minimal");
  }
  args.insert(args.end(), extra_args.begin(), extra_args.end());
  pid_ = fork();
  if (pid_ == 0) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  std::string port;
  while (std::chrono::steady_clock::now() < deadline) {
    std::ifstream in(port_file);
    if (in >> port) break;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_)
      throw std::runtime_error("the server exited during start-up");
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (port.empty()) throw std::runtime_error("the server did not write its port within 60 s");
  target_ = "127.0.0.1:" + port;
  grpc::ChannelArguments channel_args;
  channel_args.SetMaxReceiveMessageSize(64 << 20);
  channel_ = grpc::CreateCustomChannel(target_, grpc::InsecureChannelCredentials(), channel_args);
}

ServerProcess::~ServerProcess() {
  if (pid_ > 0) stop();
}

long ServerProcess::rss_kib() const {
  std::ifstream in("/proc/" + std::to_string(pid_) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

int ServerProcess::stop(double timeout_s) {
  if (pid_ <= 0) return -1;
  kill(pid_, SIGTERM);
  return wait(timeout_s);
}

void ServerProcess::signal(int number) const {
  if (pid_ > 0) kill(pid_, number);
}

int ServerProcess::wait(double timeout_s) {
  if (pid_ <= 0) return -1;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int status = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(pid_, SIGKILL);
  waitpid(pid_, &status, 0);
  pid_ = -1;
  return -1;
}

}  // namespace downpour::testing
