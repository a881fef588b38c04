// A C++ client of the Downpour server, for a simulator to embed: one connection, and a session
// object for each mode over the generated stubs (downpour/v1/downpour.grpc.pb.h). Frames come back
// as the contract's messages, their JPEG images as bytes (Frame::jpeg()).
//
//   downpour::client::Client client({"127.0.0.1:50051"});
//   downpour::client::LockstepSession session(client, request);  // closed when it goes
//   for (...) for (const auto& frame : session.step(0.05, update)) use(frame.jpeg());
//
// Errors are thrown as downpour::client::Error with the server's status code and message.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "downpour/v1/downpour.grpc.pb.h"

namespace downpour::client {

namespace v1 = ::downpour::v1;

class Error : public std::runtime_error {
 public:
  explicit Error(const grpc::Status& status);
  grpc::StatusCode code() const { return code_; }

 private:
  grpc::StatusCode code_;
};

struct Options {
  std::string target = "127.0.0.1:50051";
  std::string token;                         // a bearer token, for a server with a tokens file
  std::string tls_ca_pem;                    // the server's CA (PEM text): connect with TLS
  std::chrono::milliseconds timeout{30000};  // for each unary call
  int max_message_mb = 64;  // the largest response taken (four large views exceed gRPC's 4 MiB)
};

// Several servers may answer to one name (a headless Service): a session lives on the one that
// created it, which names itself in SessionInfo.endpoint. The client sends every later call for a
// session it created to that endpoint (same credentials), over a channel of its own; with a token
// and no TLS, only an endpoint on this machine (the token is not sent elsewhere in plaintext).
// Not movable (it holds a mutex): keep it where it is made, or in a unique_ptr.
class Client {
 public:
  explicit Client(Options options = {});

  v1::SessionInfo create_session(const v1::CreateSessionRequest& request);
  void close_session(const std::string& session_id);
  std::vector<v1::SessionInfo> list_sessions();
  v1::ServerStats stats();

  // For what this class does not wrap: the stub of the target, the stub of the server that holds
  // a session (the target unless its endpoint is another), and a context with the token and
  // timeout. Thread-safe.
  v1::Downpour::Stub& stub() { return *stub_; }
  v1::Downpour::Stub& stub_for(const std::string& session_id);
  void prepare(grpc::ClientContext& context, bool with_timeout = true) const;

 private:
  std::unique_ptr<v1::Downpour::Stub> connect(const std::string& target) const;

  Options options_;
  std::unique_ptr<v1::Downpour::Stub> stub_;
  std::mutex mutex_;
  std::map<std::string, std::string> endpoints_;  // session id -> endpoint, where not the target
  std::map<std::string, std::unique_ptr<v1::Downpour::Stub>> stubs_;  // endpoint -> its stub
};

// A lockstep session: each step applies an update, advances dt_s and returns every view's frame.
class LockstepSession {
 public:
  // The request's mode is set to lockstep.
  LockstepSession(Client& client, v1::CreateSessionRequest request);
  ~LockstepSession();  // closes the session
  LockstepSession(const LockstepSession&) = delete;
  LockstepSession& operator=(const LockstepSession&) = delete;

  const v1::SessionInfo& info() const { return info_; }
  std::vector<v1::Frame> step(double dt_s, const v1::Update& update = {});

 private:
  Client& client_;
  v1::SessionInfo info_;
};

// A realtime session: updates apply on arrival; the server renders at the session's rate and a
// reader thread hands each frame to on_frame (from WatchFrames; the views of a tick share its
// frame_number). An exception thrown by on_frame ends the reading.
class RealtimeSession {
 public:
  using FrameHandler = std::function<void(const v1::Frame&)>;
  // The request's mode is set to realtime; on_frame runs on the reader thread.
  RealtimeSession(Client& client, v1::CreateSessionRequest request, FrameHandler on_frame);
  ~RealtimeSession();  // stops reading, closes the session
  RealtimeSession(const RealtimeSession&) = delete;
  RealtimeSession& operator=(const RealtimeSession&) = delete;

  const v1::SessionInfo& info() const { return info_; }
  void update(const v1::Update& update);
  std::uint64_t frames_received() const { return received_.load(); }

 private:
  Client& client_;
  v1::SessionInfo info_;
  grpc::ClientContext watch_context_;
  std::atomic<std::uint64_t> received_{0};
  std::thread reader_;
};

}  // namespace downpour::client
