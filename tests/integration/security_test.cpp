// Security against the real server: bearer tokens and their refusals (UNAUTHENTICATED,
// PERMISSION_DENIED), session ownership, TLS and mutual TLS with certificates made for the test,
// the plaintext health port, and a server that will not listen beyond loopback unprotected.
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "downpour/v1/downpour.grpc.pb.h"
#include "grpc_health/v1/health.grpc.pb.h"
#include "tests/integration/requests.hpp"
#include "tests/integration/server_process.hpp"

namespace downpour::testing {
namespace {

using v1::Downpour;

const std::string kRig1 = "0123456789abcdef0123456789abcdef";
const std::string kRig2 = "1123456789abcdef0123456789abcdef";
const std::string kWall = "2123456789abcdef0123456789abcdef";
const std::string kOps = "3123456789abcdef0123456789abcdef";

// A folder of its own for a test's files (tokens, keys), removed at the end.
class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/downpour-security-XXXXXX";
    path_ = mkdtemp(tmpl);
  }
  ~TempDir() { std::system(("rm -rf " + path_).c_str()); }
  std::string file(const std::string& name, const std::string& text = "") const {
    const std::string p = path_ + "/" + name;
    if (!text.empty()) std::ofstream(p) << text;
    return p;
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

std::string tokens_file(const TempDir& dir) {
  return dir.file("tokens", kRig1 + " rig-1 driver\n" + kRig2 + " rig-2 driver\n" + kWall +
                                " wall viewer\n" + kOps + " ops admin\n");
}

void with_token(grpc::ClientContext* ctx, const std::string& token) {
  if (!token.empty()) ctx->AddMetadata("authorization", "Bearer " + token);
}

// Calls as one principal.
struct As {
  std::unique_ptr<Downpour::Stub> stub;
  std::string token;

  grpc::Status create(std::string* id) {
    v1::CreateSessionRequest req;
    *req.add_views() = view(v1::VIEW_RAIN, 32, 32);
    req.set_mode(v1::MODE_LOCKSTEP);
    v1::SessionInfo info;
    const grpc::Status s = unary(&Downpour::Stub::CreateSession, req, &info);
    if (id) *id = info.session_id();
    return s;
  }
  // A unary call with this principal's token.
  template <typename Request, typename Response>
  grpc::Status unary(grpc::Status (Downpour::Stub::*method)(grpc::ClientContext*, const Request&,
                                                            Response*),
                     const Request& req, Response* resp = nullptr) {
    grpc::ClientContext ctx;
    with_token(&ctx, token);
    Response ignored;
    return (stub.get()->*method)(&ctx, req, resp ? resp : &ignored);
  }
  grpc::Status update(const std::string& id) {
    v1::UpdateRequest req;
    req.set_session_id(id);
    *req.mutable_update() = drive_update(0.0);
    return unary(&Downpour::Stub::Update, req);
  }
  grpc::Status step(const std::string& id) {
    v1::StepRequest req;
    req.set_session_id(id);
    req.set_dt_s(0.05);
    return unary(&Downpour::Stub::Step, req);
  }
  grpc::Status drive(const std::string& id) {
    grpc::ClientContext ctx;
    with_token(&ctx, token);
    auto stream = stub->Drive(&ctx);
    v1::DriveRequest req;
    req.set_session_id(id);
    req.set_dt_s(0.05);
    stream->Write(req);
    stream->WritesDone();
    v1::DriveResponse resp;
    while (stream->Read(&resp)) {
    }
    return stream->Finish();
  }
  grpc::Status watch(const std::string& id) {
    grpc::ClientContext ctx;
    with_token(&ctx, token);
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(500));
    v1::WatchFramesRequest req;
    req.set_session_id(id);
    auto reader = stub->WatchFrames(&ctx, req);
    v1::Frame frame;
    if (reader->Read(&frame)) ctx.TryCancel();  // a frame came: it was let in
    const grpc::Status s = reader->Finish();
    // Watching worked if the stream was only ended by us (or its deadline).
    if (s.error_code() == grpc::StatusCode::CANCELLED ||
        s.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED)
      return grpc::Status::OK;
    return s;
  }
  grpc::Status close(const std::string& id) {
    v1::CloseSessionRequest req;
    req.set_session_id(id);
    return unary(&Downpour::Stub::CloseSession, req);
  }
  std::set<std::string> listed(grpc::Status* status = nullptr) {
    v1::ListSessionsResponse resp;
    const grpc::Status s = unary(&Downpour::Stub::ListSessions, v1::ListSessionsRequest(), &resp);
    if (status) *status = s;
    std::set<std::string> ids;
    for (const auto& info : resp.sessions()) ids.insert(info.session_id() + "@" + info.owner());
    return ids;
  }
  grpc::Status stats() { return unary(&Downpour::Stub::GetStats, v1::GetStatsRequest()); }
};

TEST(SecurityTest, EveryCallNeedsAKnownToken) {
  TempDir dir;
  ServerProcess server({"--tokens-file", tokens_file(dir)});
  for (const std::string& token : {std::string(), std::string("not-a-token-of-this-server")}) {
    As anon{Downpour::NewStub(server.channel()), token};
    const std::string label = token.empty() ? "no token" : "an unknown token";
    EXPECT_EQ(anon.create(nullptr).error_code(), grpc::StatusCode::UNAUTHENTICATED) << label;
    grpc::Status s;
    anon.listed(&s);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::UNAUTHENTICATED) << label;
    EXPECT_EQ(anon.stats().error_code(), grpc::StatusCode::UNAUTHENTICATED) << label;
    EXPECT_EQ(anon.update("s1-x").error_code(), grpc::StatusCode::UNAUTHENTICATED) << label;
    EXPECT_EQ(anon.step("s1-x").error_code(), grpc::StatusCode::UNAUTHENTICATED) << label;
    EXPECT_EQ(anon.drive("s1-x").error_code(), grpc::StatusCode::UNAUTHENTICATED) << label;
    EXPECT_EQ(anon.watch("s1-x").error_code(), grpc::StatusCode::UNAUTHENTICATED) << label;
    EXPECT_EQ(anon.close("s1-x").error_code(), grpc::StatusCode::UNAUTHENTICATED) << label;
  }
  // Health answers without a token (load balancers and probes have none).
  auto health = grpc::health::v1::Health::NewStub(server.channel());
  grpc::ClientContext ctx;
  grpc::health::v1::HealthCheckResponse h;
  EXPECT_TRUE(health->Check(&ctx, grpc::health::v1::HealthCheckRequest(), &h).ok());
  EXPECT_EQ(server.stop(15.0), 0);
}

TEST(SecurityTest, OnlyTheOwnerDrivesASessionAViewerWatchesAndAnAdminMayDoAll) {
  TempDir dir;
  ServerProcess server({"--tokens-file", tokens_file(dir)});
  As rig1{Downpour::NewStub(server.channel()), kRig1};
  As rig2{Downpour::NewStub(server.channel()), kRig2};
  As wall{Downpour::NewStub(server.channel()), kWall};
  As ops{Downpour::NewStub(server.channel()), kOps};
  std::string mine, theirs;
  ASSERT_TRUE(rig1.create(&mine).ok());
  ASSERT_TRUE(rig2.create(&theirs).ok());

  // The owner does everything to its own session.
  EXPECT_TRUE(rig1.update(mine).ok());
  EXPECT_TRUE(rig1.step(mine).ok());
  EXPECT_TRUE(rig1.drive(mine).ok());
  EXPECT_TRUE(rig1.watch(mine).ok());
  // Another driver: nothing, and does not even see it listed.
  for (const grpc::Status& s :
       {rig2.update(mine), rig2.step(mine), rig2.drive(mine), rig2.watch(mine), rig2.close(mine)}) {
    EXPECT_EQ(s.error_code(), grpc::StatusCode::PERMISSION_DENIED) << s.error_message();
    EXPECT_NE(s.error_message().find("belongs to another client"), std::string::npos);
  }
  EXPECT_EQ(rig1.listed(), std::set<std::string>{mine + "@rig-1"});
  EXPECT_EQ(rig2.listed(), std::set<std::string>{theirs + "@rig-2"});
  // A viewer watches and lists any session, and changes none.
  EXPECT_TRUE(wall.watch(mine).ok());
  EXPECT_EQ(wall.listed(), (std::set<std::string>{mine + "@rig-1", theirs + "@rig-2"}));
  EXPECT_EQ(wall.create(nullptr).error_code(), grpc::StatusCode::PERMISSION_DENIED);
  for (const grpc::Status& s :
       {wall.update(mine), wall.step(mine), wall.drive(mine), wall.close(mine)})
    EXPECT_EQ(s.error_code(), grpc::StatusCode::PERMISSION_DENIED) << s.error_message();
  EXPECT_TRUE(wall.stats().ok());
  // An admin does all of it to anyone's session.
  EXPECT_TRUE(ops.step(theirs).ok());
  EXPECT_TRUE(ops.close(theirs).ok());
  EXPECT_TRUE(rig1.close(mine).ok());
  EXPECT_TRUE(ops.listed().empty());
  EXPECT_EQ(server.stop(15.0), 0);
}

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A CA, a server certificate for "localhost" and a client certificate, both signed by the CA.
void make_certificates(const TempDir& dir) {
  const std::string d = dir.path();
  dir.file("server.ext", "subjectAltName=DNS:localhost\n");
  const std::string script =
      "set -e; cd " + d +
      "; openssl req -x509 -newkey rsa:2048 -nodes -keyout ca.key -out ca.crt -days 1 "
      "-subj /CN=test-ca 2>/dev/null"
      "; openssl req -newkey rsa:2048 -nodes -keyout server.key -out server.csr "
      "-subj /CN=localhost 2>/dev/null"
      "; openssl x509 -req -in server.csr -CA ca.crt -CAkey ca.key -CAcreateserial "
      "-out server.crt -days 1 -extfile server.ext 2>/dev/null"
      "; openssl req -newkey rsa:2048 -nodes -keyout client.key -out client.csr "
      "-subj /CN=rig-1 2>/dev/null"
      "; openssl x509 -req -in client.csr -CA ca.crt -CAkey ca.key -CAcreateserial "
      "-out client.crt -days 1 2>/dev/null";
  ASSERT_EQ(std::system(("bash -c \"" + script + "\"").c_str()), 0) << "openssl failed";
}

std::shared_ptr<grpc::Channel> tls_channel(const std::string& target, const TempDir& dir,
                                           bool client_certificate) {
  grpc::SslCredentialsOptions options;
  options.pem_root_certs = read(dir.path() + "/ca.crt");
  if (client_certificate) {
    options.pem_private_key = read(dir.path() + "/client.key");
    options.pem_cert_chain = read(dir.path() + "/client.crt");
  }
  grpc::ChannelArguments args;
  args.SetSslTargetNameOverride("localhost");
  args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);
  return grpc::CreateCustomChannel(target, grpc::SslCredentials(options), args);
}

TEST(SecurityTest, TlsAndMutualTlsWithAPlaintextHealthPortBeside) {
  TempDir dir;
  make_certificates(dir);
  const int health_port = free_port();
  ServerProcess server({"--tls-cert", dir.path() + "/server.crt", "--tls-key",
                        dir.path() + "/server.key", "--tls-client-ca", dir.path() + "/ca.crt",
                        "--tokens-file", tokens_file(dir), "--health-listen",
                        "127.0.0.1:" + std::to_string(health_port)});
  auto call = [&](std::shared_ptr<grpc::Channel> channel) {
    As rig{Downpour::NewStub(channel), kRig1};
    return rig.stats();
  };
  // With the CA's client certificate and a token: served.
  EXPECT_TRUE(call(tls_channel(server.target(), dir, true)).ok());
  // TLS without a client certificate, or plaintext: the handshake fails.
  EXPECT_EQ(call(tls_channel(server.target(), dir, false)).error_code(),
            grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(
      call(grpc::CreateChannel(server.target(), grpc::InsecureChannelCredentials())).error_code(),
      grpc::StatusCode::UNAVAILABLE);
  // Probes reach health alone, in plaintext, on its own port.
  const auto plain = grpc::CreateChannel("127.0.0.1:" + std::to_string(health_port),
                                         grpc::InsecureChannelCredentials());
  grpc::ClientContext ctx;
  grpc::health::v1::HealthCheckResponse h;
  ASSERT_TRUE(grpc::health::v1::Health::NewStub(plain)
                  ->Check(&ctx, grpc::health::v1::HealthCheckRequest(), &h)
                  .ok());
  EXPECT_EQ(h.status(), grpc::health::v1::HealthCheckResponse::SERVING);
  EXPECT_EQ(call(plain).error_code(), grpc::StatusCode::UNIMPLEMENTED);  // no Downpour there
  EXPECT_EQ(server.stop(15.0), 0);
}

// A viewer watching someone else's session does not keep it alive: once its driver is gone the
// lease runs out however often the viewer looks; the owner's own requests renew it.
TEST(SecurityTest, AViewerWatchingDoesNotKeepAnotherClientsSessionAlive) {
  TempDir dir;
  const double lease_s = 2.0 * time_scale();
  ServerProcess server(
      {"--tokens-file", tokens_file(dir), "--session-idle-timeout-s", std::to_string(lease_s)});
  As rig1{Downpour::NewStub(server.channel()), kRig1};
  As wall{Downpour::NewStub(server.channel()), kWall};
  std::string kept, left;
  ASSERT_TRUE(rig1.create(&kept).ok());
  ASSERT_TRUE(rig1.create(&left).ok());
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto since_t0 = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  // The owner renews `kept` from its own thread, eight times a lease, so that how long the
  // viewer's calls take (a sanitizer build is slow) cannot decide the test.
  std::atomic<bool> done{false};
  std::string renewal_failure;
  double longest_gap_s = 0.0;
  std::thread owner([&] {
    double last = 0.0;
    while (!done.load()) {
      const grpc::Status s = rig1.update(kept);
      const double now = since_t0();
      longest_gap_s = std::max(longest_gap_s, now - last);
      last = now;
      if (!s.ok() && renewal_failure.empty()) {
        renewal_failure = std::to_string(s.error_code()) + " " + s.error_message() + " at " +
                          std::to_string(now) + " s";
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(static_cast<int>(125 * lease_s)));
    }
  });
  // The viewer watches `left` over and over until the server closes it, for six leases at most.
  grpc::Status watched;
  while (since_t0() < 6.0 * lease_s) {
    watched = wall.watch(left);  // 0.5 s each while the session is there
    if (watched.error_code() == grpc::StatusCode::NOT_FOUND) break;
  }
  const double closed_after_s = since_t0();
  done = true;
  owner.join();
  EXPECT_EQ(watched.error_code(), grpc::StatusCode::NOT_FOUND)
      << "the viewer's watching kept the session for " << closed_after_s << " s";
  EXPECT_GE(closed_after_s, lease_s - 0.2) << "closed before its lease ran out";
  EXPECT_TRUE(renewal_failure.empty())
      << "the owner's renewal failed: " << renewal_failure << "; longest gap between renewals "
      << longest_gap_s << " s of a " << lease_s << " s lease";
  const std::set<std::string> ids = rig1.listed();
  EXPECT_TRUE(ids.count(kept + "@rig-1"));
  EXPECT_FALSE(ids.count(left + "@rig-1"));
  EXPECT_EQ(server.stop(15.0), 0);
}

TEST(SecurityTest, ListeningBeyondLoopbackNeedsTlsAndTokens) {
  TempDir dir;
  EXPECT_THROW(ServerProcess({"--listen", "0.0.0.0:0"}), std::runtime_error);
  EXPECT_THROW(ServerProcess({"--listen", "0.0.0.0:0", "--tokens-file", tokens_file(dir)}),
               std::runtime_error);
  EXPECT_THROW(ServerProcess({"--tokens-file", dir.file("bad", "short rig driver\n")}),
               std::runtime_error);
}

}  // namespace
}  // namespace downpour::testing
