#include "downpour/client.hpp"

#include <algorithm>
#include <utility>

namespace downpour::client {

Error::Error(const grpc::Status& status)
    : std::runtime_error(status.error_message()), code_(status.error_code()) {}

namespace {

void check(const grpc::Status& status) {
  if (!status.ok()) throw Error(status);
}

// Whether a gRPC target names this machine (a unix socket, localhost, 127.x, ::1).
bool is_loopback(std::string target) {
  if (target.rfind("unix:", 0) == 0) return true;
  for (const char* scheme : {"dns:///", "ipv4:", "ipv6:"}) {
    if (target.rfind(scheme, 0) == 0) target = target.substr(std::string(scheme).size());
  }
  std::string host = target;
  if (!host.empty() && host.front() == '[') {
    host = host.substr(1, host.find(']') - 1);
  } else if (std::count(host.begin(), host.end(), ':') == 1) {
    host = host.substr(0, host.find(':'));
  }
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

}  // namespace

Client::Client(Options options) : options_(std::move(options)) { stub_ = connect(options_.target); }

std::unique_ptr<v1::Downpour::Stub> Client::connect(const std::string& target) const {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(options_.max_message_mb << 20);
  std::shared_ptr<grpc::ChannelCredentials> credentials;
  if (options_.tls_ca_pem.empty()) {
    credentials = grpc::InsecureChannelCredentials();
  } else {
    grpc::SslCredentialsOptions tls;
    tls.pem_root_certs = options_.tls_ca_pem;
    credentials = grpc::SslCredentials(tls);
  }
  return v1::Downpour::NewStub(grpc::CreateCustomChannel(target, credentials, args));
}

v1::Downpour::Stub& Client::stub_for(const std::string& session_id) {
  std::lock_guard lock(mutex_);
  const auto endpoint = endpoints_.find(session_id);
  if (endpoint == endpoints_.end()) return *stub_;
  std::unique_ptr<v1::Downpour::Stub>& stub = stubs_[endpoint->second];
  if (!stub) stub = connect(endpoint->second);
  return *stub;
}

void Client::prepare(grpc::ClientContext& context, bool with_timeout) const {
  if (!options_.token.empty()) context.AddMetadata("authorization", "Bearer " + options_.token);
  if (with_timeout) context.set_deadline(std::chrono::system_clock::now() + options_.timeout);
}

v1::SessionInfo Client::create_session(const v1::CreateSessionRequest& request) {
  grpc::ClientContext context;
  prepare(context);
  v1::SessionInfo info;
  check(stub_->CreateSession(&context, request, &info));
  // The token goes to a server-named endpoint only over TLS (its certificate checked against
  // our CA) or to this machine.
  const bool may_follow =
      !options_.tls_ca_pem.empty() || options_.token.empty() || is_loopback(info.endpoint());
  if (!info.endpoint().empty() && info.endpoint() != options_.target && may_follow) {
    std::lock_guard lock(mutex_);
    endpoints_[info.session_id()] = info.endpoint();
  }
  return info;
}

void Client::close_session(const std::string& session_id) {
  grpc::ClientContext context;
  prepare(context);
  v1::CloseSessionRequest request;
  request.set_session_id(session_id);
  v1::CloseSessionResponse response;
  const grpc::Status status = stub_for(session_id).CloseSession(&context, request, &response);
  if (status.ok() || status.error_code() == grpc::StatusCode::NOT_FOUND) {
    std::lock_guard lock(mutex_);  // gone: a failed close may be tried again, at the same place
    endpoints_.erase(session_id);
  }
  check(status);
}

std::vector<v1::SessionInfo> Client::list_sessions() {
  grpc::ClientContext context;
  prepare(context);
  v1::ListSessionsResponse response;
  check(stub_->ListSessions(&context, v1::ListSessionsRequest(), &response));
  return {response.sessions().begin(), response.sessions().end()};
}

v1::ServerStats Client::stats() {
  grpc::ClientContext context;
  prepare(context);
  v1::ServerStats stats;
  check(stub_->GetStats(&context, v1::GetStatsRequest(), &stats));
  return stats;
}

LockstepSession::LockstepSession(Client& client, v1::CreateSessionRequest request)
    : client_(client) {
  request.set_mode(v1::MODE_LOCKSTEP);
  info_ = client_.create_session(request);
}

LockstepSession::~LockstepSession() {
  try {
    client_.close_session(info_.session_id());
  } catch (const Error&) {
    // Gone already (closed for idleness, the server drained): nothing to close.
  }
}

std::vector<v1::Frame> LockstepSession::step(double dt_s, const v1::Update& update) {
  grpc::ClientContext context;
  client_.prepare(context);
  v1::StepRequest request;
  request.set_session_id(info_.session_id());
  *request.mutable_update() = update;
  request.set_dt_s(dt_s);
  v1::StepResponse response;
  check(client_.stub_for(info_.session_id()).Step(&context, request, &response));
  return {response.frames().begin(), response.frames().end()};
}

RealtimeSession::RealtimeSession(Client& client, v1::CreateSessionRequest request,
                                 FrameHandler on_frame)
    : client_(client) {
  request.set_mode(v1::MODE_REALTIME);
  info_ = client_.create_session(request);
  client_.prepare(watch_context_, false);
  reader_ = std::thread([this, on_frame = std::move(on_frame)] {
    v1::WatchFramesRequest watch;
    watch.set_session_id(info_.session_id());
    auto stream = client_.stub_for(info_.session_id()).WatchFrames(&watch_context_, watch);
    v1::Frame frame;
    while (stream->Read(&frame)) {
      ++received_;
      try {
        if (on_frame) on_frame(frame);
      } catch (...) {
        watch_context_.TryCancel();  // the handler gave up: so does the reading
        break;
      }
    }
    stream->Finish();
  });
}

RealtimeSession::~RealtimeSession() {
  watch_context_.TryCancel();
  if (reader_.joinable()) reader_.join();
  try {
    client_.close_session(info_.session_id());
  } catch (const Error&) {
  }
}

void RealtimeSession::update(const v1::Update& update) {
  grpc::ClientContext context;
  client_.prepare(context);
  v1::UpdateRequest request;
  request.set_session_id(info_.session_id());
  *request.mutable_update() = update;
  v1::UpdateResponse response;
  check(client_.stub_for(info_.session_id()).Update(&context, request, &response));
}

}  // namespace downpour::client
