// Who is calling, and what they may do. Clients present a bearer token ("authorization: Bearer
// <token>" metadata); a tokens file names each token's principal and roles:
//
//   # token (16+ characters)           principal     roles (comma-separated)
//   9f2c41d07a6e4b0c8d1e5f3a2b7c9d04   sim-rig-1     driver
//   c0ffee5e7a4b49d2a1e8f6b3d5c7a9e1   viewer-wall   viewer
//   4d3c2b1a0f9e8d7c6b5a49382716f5e4   ops           admin
//
// driver: creates sessions and drives, watches and closes its own. viewer: watches and lists any
// session, changes none. admin: all of it, for every session. Without a tokens file every client
// is one principal ("local") with every role: what a server on 127.0.0.1 has always done.
#pragma once

#include <string>
#include <vector>

#include <grpcpp/server_context.h>
#include <grpcpp/support/status.h>

namespace downpour::rpc {

enum Role : unsigned { kDriver = 1u, kViewer = 2u, kAdmin = 4u };

struct Principal {
  std::string name;
  unsigned roles = 0;
  bool has(Role r) const { return (roles & r) != 0; }
};

class Authenticator {
 public:
  Authenticator() = default;  // open: no tokens required
  // Reads a tokens file; throws std::runtime_error naming the line of a bad entry (a short
  // token, an unknown role, a token given twice).
  static Authenticator from_file(const std::string& path);
  static Authenticator from_text(const std::string& text, const std::string& origin);

  bool requires_tokens() const { return !entries_.empty(); }
  std::size_t token_count() const { return entries_.size(); }
  // The caller's principal, or UNAUTHENTICATED saying what is missing.
  grpc::Status authenticate(const grpc::ServerContextBase& ctx, Principal* out) const;
  // The same from a bare metadata value (tests, tools).
  grpc::Status authenticate_header(const std::string* authorization, Principal* out) const;

 private:
  struct Entry {
    std::string token;
    Principal principal;
  };
  std::vector<Entry> entries_;
};

// Whether a listen address ("host:port", "[v6]:port", "unix:path") reaches only this machine:
// 127.0.0.0/8, ::1, ::ffff:127.x.y.z, the name "localhost", or a Unix socket. Any other name may
// resolve anywhere, so it is not loopback.
bool loopback_only(const std::string& listen);

}  // namespace downpour::rpc
