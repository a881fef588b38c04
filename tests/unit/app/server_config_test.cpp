#include "server/app/server_config.hpp"

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "server/app/log_format.hpp"

namespace downpour::app {
namespace {

std::optional<ServerConfig> parse(std::vector<std::string> args, int* exit_code) {
  args.insert(args.begin(), "downpour-server");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  return parse_config(static_cast<int>(argv.size()), argv.data(), exit_code);
}

TEST(ServerConfigTest, NamedChoicesAreReadByName) {
  int code = -1;
  auto c =
      parse({"--renderer", "Surfaceless", "--spray-smoothing", "bilateral", "--warm-up", "Minimal"},
            &code);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->renderer, render::EglPlatformChoice::kSurfaceless);
  EXPECT_EQ(c->spray_smoothing, render::SpraySmoothing::kBilateral);
  EXPECT_EQ(c->warm_up, render::WarmUp::kMinimal);
  EXPECT_EQ(parse({}, &code)->warm_up, render::WarmUp::kFull);
  EXPECT_FALSE(parse({"--renderer", "vulkan"}, &code));
  EXPECT_NE(code, 0);
  EXPECT_FALSE(parse({"--warm-up", "none"}, &code));
  EXPECT_NE(code, 0);
}

TEST(ServerConfigTest, HelpNamesTheChoicesAndVersionIsTheProjects) {
  ::testing::internal::CaptureStdout();
  int code = -1;
  EXPECT_FALSE(parse({"--help"}, &code));
  const std::string help = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(code, 0);
  EXPECT_NE(help.find("{auto,device,surfaceless}"), std::string::npos) << help;
  EXPECT_EQ(help.find("ENUM"), std::string::npos) << help;
  EXPECT_EQ(help.find("->"), std::string::npos) << help;
  for (const char* flag : {"--config", "--metrics-listen", "--advertise", "--log-format"})
    EXPECT_NE(help.find(flag), std::string::npos) << flag;

  ::testing::internal::CaptureStdout();
  EXPECT_FALSE(parse({"--version"}, &code));
  const std::string version = ::testing::internal::GetCapturedStdout();
  EXPECT_EQ(code, 0);
  EXPECT_EQ(version, std::string("downpour-server ") + kVersion + "\n");
  EXPECT_NE(std::string(kVersion).find('.'), std::string::npos);
}

TEST(ServerConfigTest, AConfigFileSetsFlagsAndTheCommandLineWins) {
  char path[] = "/tmp/downpour_config_XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  close(fd);
  std::ofstream(path) << "# a deployment's flags\nmax-sessions = 3\nrenderer = \"device\"\n"
                         "metrics-listen = \"127.0.0.1:9100\"\nmax-fps = 50\n";
  int code = -1;
  auto c = parse({"--config", path, "--max-fps", "25"}, &code);
  std::remove(path);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->max_sessions, 3);
  EXPECT_EQ(c->renderer, render::EglPlatformChoice::kDevice);
  EXPECT_EQ(c->metrics_listen, "127.0.0.1:9100");
  EXPECT_EQ(c->max_fps, 25.0);
  EXPECT_FALSE(parse({"--config", "/nonexistent/downpour.toml"}, &code));
  EXPECT_EQ(code, 2);
}

TEST(ServerConfigTest, TheConfigFileMayComeFromTheEnvironmentAndWinsOverItsFlags) {
  char path[] = "/tmp/downpour_config_XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  close(fd);
  std::ofstream(path) << "max-sessions = 3\n";
  setenv("DOWNPOUR_CONFIG", path, 1);
  setenv("DOWNPOUR_MAX_SESSIONS", "5", 1);
  setenv("DOWNPOUR_MAX_FPS", "40", 1);
  int code = -1;
  auto c = parse({}, &code);
  unsetenv("DOWNPOUR_CONFIG");
  unsetenv("DOWNPOUR_MAX_SESSIONS");
  unsetenv("DOWNPOUR_MAX_FPS");
  std::remove(path);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->max_sessions, 3);  // the file's
  EXPECT_EQ(c->max_fps, 40.0);    // the environment's, where the file says nothing
}

TEST(LogFormatTest, JsonFieldsNameTheSessionAndEscapeTheMessage) {
  EXPECT_EQ(json_log_fields("renderer: llvmpipe"), R"("msg":"renderer: llvmpipe")");
  EXPECT_EQ(json_log_fields("session 4f2a started: lockstep"),
            R"("session":"4f2a","msg":"session 4f2a started: lockstep")");
  EXPECT_EQ(json_log_fields("session ab-1: a frame failed"),
            R"("session":"ab-1","msg":"session ab-1: a frame failed")");
  EXPECT_EQ(json_log_fields("sessions: 3"), R"("msg":"sessions: 3")");
  EXPECT_EQ(json_log_fields("say \"hi\"\\\n\x01"), R"("msg":"say \"hi\"\\\n\u0001")");
}

}  // namespace
}  // namespace downpour::app
