#include "server/rpc/auth.hpp"

#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace downpour::rpc {
namespace {

const char* const kTokens = R"(# token                          principal  roles
0123456789abcdef0123456789abcdef  rig-1      driver
fedcba9876543210fedcba9876543210  wall       viewer   # the lobby screen

aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa  ops        admin
bbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbb  rig-2      driver,viewer
)";

TEST(AuthTest, WithoutTokensEveryClientIsOneLocalPrincipalWithEveryRole) {
  const Authenticator open;
  EXPECT_FALSE(open.requires_tokens());
  Principal p;
  ASSERT_TRUE(open.authenticate_header(nullptr, &p).ok());
  EXPECT_EQ(p.name, "local");
  EXPECT_TRUE(p.has(kDriver) && p.has(kViewer) && p.has(kAdmin));
}

TEST(AuthTest, ATokenNamesItsPrincipalAndRoles) {
  const Authenticator auth = Authenticator::from_text(kTokens, "tokens");
  EXPECT_EQ(auth.token_count(), 4u);
  Principal p;
  std::string header = "Bearer 0123456789abcdef0123456789abcdef";
  ASSERT_TRUE(auth.authenticate_header(&header, &p).ok());
  EXPECT_EQ(p.name, "rig-1");
  EXPECT_TRUE(p.has(kDriver));
  EXPECT_FALSE(p.has(kViewer));
  EXPECT_FALSE(p.has(kAdmin));
  header = "Bearer fedcba9876543210fedcba9876543210";
  ASSERT_TRUE(auth.authenticate_header(&header, &p).ok());
  EXPECT_EQ(p.name, "wall");
  EXPECT_TRUE(p.has(kViewer));
  EXPECT_FALSE(p.has(kDriver));
  header = "Bearer aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa";
  ASSERT_TRUE(auth.authenticate_header(&header, &p).ok());
  EXPECT_TRUE(p.has(kAdmin) && p.has(kDriver) && p.has(kViewer));  // admin implies the others
  header = "Bearer bbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbb";
  ASSERT_TRUE(auth.authenticate_header(&header, &p).ok());
  EXPECT_TRUE(p.has(kDriver) && p.has(kViewer));
  EXPECT_FALSE(p.has(kAdmin));
}

TEST(AuthTest, MissingMalformedAndUnknownTokensAreUnauthenticated) {
  const Authenticator auth = Authenticator::from_text(kTokens, "tokens");
  Principal p;
  EXPECT_EQ(auth.authenticate_header(nullptr, &p).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  for (const std::string header :
       {"0123456789abcdef0123456789abcdef", "Basic 0123456789abcdef0123456789abcdef",
        "Bearer 0123456789abcdef0123456789abcdeF", "Bearer 0123456789abcdef",
        "Bearer 0123456789abcdef0123456789abcdef0", "Bearer ", ""}) {
    const grpc::Status s = auth.authenticate_header(&header, &p);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::UNAUTHENTICATED) << "'" << header << "'";
    EXPECT_FALSE(s.error_message().empty());
  }
}

TEST(AuthTest, ABadTokensFileIsRefusedNamingTheLine) {
  auto refused = [](const std::string& text) {
    try {
      Authenticator::from_text(text, "t");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refused("short-token rig driver\n").find("t:1: a token needs at least 16"),
            std::string::npos);
  EXPECT_NE(refused("# c\n0123456789abcdef0123456789abcdef rig pilot\n").find("t:2: unknown role"),
            std::string::npos);
  EXPECT_NE(refused("0123456789abcdef0123456789abcdef rig\n").find("t:1: expected"),
            std::string::npos);
  EXPECT_NE(refused("0123456789abcdef0123456789abcdef a driver\n"
                    "0123456789abcdef0123456789abcdef b viewer\n")
                .find("t:2: this token is given twice"),
            std::string::npos);
  EXPECT_NE(refused("# nothing\n").find("no tokens"), std::string::npos);
  EXPECT_THROW(Authenticator::from_file("/nonexistent/tokens"), std::runtime_error);
}

TEST(AuthTest, TheSchemeIsCaseInsensitiveAndATokenMayHoldAHash) {
  const Authenticator auth =
      Authenticator::from_text("ab#cdef0123456789abcdef rig driver  # a comment\n", "t");
  Principal p;
  for (const std::string header :
       {"Bearer ab#cdef0123456789abcdef", "bearer ab#cdef0123456789abcdef",
        "BEARER ab#cdef0123456789abcdef"}) {
    ASSERT_TRUE(auth.authenticate_header(&header, &p).ok()) << header;
    EXPECT_EQ(p.name, "rig");
  }
}

TEST(AuthTest, OnlyLoopbackAddressesAndUnixSocketsCountAsLoopback) {
  for (const char* listen : {"127.0.0.1:50051", "127.1.2.3:1", "localhost:50051", "[::1]:50051",
                             "[::ffff:127.0.0.1]:9", "unix:/run/downpour.sock"}) {
    EXPECT_TRUE(loopback_only(listen)) << listen;
  }
  for (const char* listen :
       {"0.0.0.0:50051", "[::]:50051", "10.0.0.7:50051", "127.evil.example:50051",
        "127.0.0.1.example:1", "localhost.example:1", "[::ffff:10.0.0.1]:9", "example.com:50051"}) {
    EXPECT_FALSE(loopback_only(listen)) << listen;
  }
}

}  // namespace
}  // namespace downpour::rpc
