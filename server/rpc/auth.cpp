#include "server/rpc/auth.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <cctype>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>

namespace downpour::rpc {

namespace {

constexpr std::size_t kMinTokenLength = 16;
constexpr std::size_t kBearerLength = 7;  // "Bearer "

// Compares in time that depends only on the stored token's length (not on where the first
// difference is, nor on the presented length), so that a token is not guessed byte by byte.
bool same_secret(const std::string& stored, const std::string& presented) {
  unsigned diff = stored.size() == presented.size() ? 0u : 1u;
  for (std::size_t i = 0; i < stored.size(); ++i) {
    const char p = i < presented.size() ? presented[i] : '\0';
    diff |= static_cast<unsigned char>(stored[i] ^ p);
  }
  return diff == 0;
}

// The scheme name is case-insensitive (RFC 7235): "Bearer", "bearer", "BEARER".
bool starts_with_bearer(const std::string& value) {
  constexpr std::string_view kScheme = "bearer ";
  if (value.size() < kScheme.size()) return false;
  for (std::size_t i = 0; i < kScheme.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(value[i])) != kScheme[i]) return false;
  }
  return true;
}

// A '#' starts a comment at the start of a field, so a token may contain one.
void strip_comment(std::string* line) {
  for (std::size_t i = 0; i < line->size(); ++i) {
    if ((*line)[i] == '#' && (i == 0 || std::isspace(static_cast<unsigned char>((*line)[i - 1])))) {
      line->erase(i);
      return;
    }
  }
}

unsigned parse_roles(const std::string& text, const std::string& where) {
  unsigned roles = 0;
  std::stringstream in(text);
  std::string role;
  while (std::getline(in, role, ',')) {
    if (role == "driver") {
      roles |= kDriver;
    } else if (role == "viewer") {
      roles |= kViewer;
    } else if (role == "admin") {
      roles |= kAdmin | kDriver | kViewer;
    } else {
      throw std::runtime_error(where + ": unknown role '" + role +
                               "' (driver, viewer or admin, comma-separated)");
    }
  }
  if (roles == 0) throw std::runtime_error(where + ": no role");
  return roles;
}

}  // namespace

Authenticator Authenticator::from_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read the tokens file");
  std::stringstream text;
  text << in.rdbuf();
  return from_text(text.str(), path);
}

Authenticator Authenticator::from_text(const std::string& text, const std::string& origin) {
  Authenticator a;
  std::stringstream lines(text);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    strip_comment(&line);
    std::stringstream fields(line);
    std::string token, name, roles, extra;
    if (!(fields >> token)) continue;  // blank or comment
    const std::string where = origin + ":" + std::to_string(number);
    if (!(fields >> name >> roles) || (fields >> extra))
      throw std::runtime_error(where + ": expected 'token principal roles'");
    if (token.size() < kMinTokenLength) {
      throw std::runtime_error(where + ": a token needs at least " +
                               std::to_string(kMinTokenLength) +
                               " characters (openssl rand -hex 16 makes one)");
    }
    for (const Entry& e : a.entries_) {
      if (e.token == token) throw std::runtime_error(where + ": this token is given twice");
    }
    a.entries_.push_back({token, {name, parse_roles(roles, where)}});
  }
  if (a.entries_.empty()) throw std::runtime_error(origin + ": no tokens");
  return a;
}

grpc::Status Authenticator::authenticate(const grpc::ServerContextBase& ctx, Principal* out) const {
  if (!requires_tokens()) return authenticate_header(nullptr, out);
  const auto& metadata = ctx.client_metadata();
  const auto it = metadata.find("authorization");
  if (it == metadata.end()) return authenticate_header(nullptr, out);
  const std::string value(it->second.data(), it->second.size());
  return authenticate_header(&value, out);
}

grpc::Status Authenticator::authenticate_header(const std::string* authorization,
                                                Principal* out) const {
  if (!requires_tokens()) {
    *out = {"local", kDriver | kViewer | kAdmin};
    return grpc::Status::OK;
  }
  if (!authorization) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "this server needs a token: send 'authorization: Bearer <token>'");
  }
  if (!starts_with_bearer(*authorization)) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "authorization: expected 'Bearer <token>'");
  }
  const std::string token = authorization->substr(kBearerLength);
  const Entry* found = nullptr;
  for (const Entry& e : entries_) {  // every entry, match or not
    if (same_secret(e.token, token)) found = &e;
  }
  if (!found) return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "unknown token");
  *out = found->principal;
  return grpc::Status::OK;
}

bool loopback_only(const std::string& listen) {
  if (listen.rfind("unix:", 0) == 0) return true;
  std::string host = listen.substr(0, listen.rfind(':'));
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
    host = host.substr(1, host.size() - 2);
  if (host == "localhost") return true;  // the name itself, never one that merely starts so
  in_addr v4{};
  if (inet_pton(AF_INET, host.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (inet_pton(AF_INET6, host.c_str(), &v6) != 1) return false;  // a host name: may be anything
  if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
  return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
}

}  // namespace downpour::rpc
