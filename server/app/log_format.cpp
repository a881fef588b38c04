#include "server/app/log_format.hpp"

#include <cctype>
#include <cstdio>
#include <memory>

#include <spdlog/pattern_formatter.h>
#include <spdlog/spdlog.h>

namespace downpour::app {

namespace {

void append_escaped(std::string_view text, std::string& out) {
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char code[8];
          std::snprintf(code, sizeof code, "\\u%04x", static_cast<unsigned char>(c));
          out += code;
        } else {
          out += c;  // UTF-8 passes through
        }
    }
  }
}

// The session id a line starts with, or empty.
std::string_view session_of(std::string_view message) {
  constexpr std::string_view kPrefix = "session ";
  if (message.substr(0, kPrefix.size()) != kPrefix) return {};
  const std::string_view rest = message.substr(kPrefix.size());
  std::size_t n = 0;
  while (n < rest.size() && n < 64 &&
         (std::isalnum(static_cast<unsigned char>(rest[n])) || rest[n] == '-' || rest[n] == '_'))
    ++n;
  if (n == 0 || n >= rest.size() || (rest[n] != ':' && rest[n] != ' ')) return {};
  return rest.substr(0, n);
}

// %* in the pattern: the message's JSON fields.
class JsonFields final : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& msg, const std::tm&,
              spdlog::memory_buf_t& dest) override {
    const std::string fields =
        json_log_fields(std::string_view(msg.payload.data(), msg.payload.size()));
    dest.append(fields.data(), fields.data() + fields.size());
  }
  std::unique_ptr<custom_flag_formatter> clone() const override {
    return std::make_unique<JsonFields>();
  }
};

}  // namespace

std::string json_log_fields(std::string_view message) {
  std::string out;
  if (const std::string_view id = session_of(message); !id.empty()) {
    out += "\"session\":\"";
    append_escaped(id, out);
    out += "\",";
  }
  out += "\"msg\":\"";
  append_escaped(message, out);
  out += '"';
  return out;
}

void set_log_format(const std::string& format) {
  if (format != "json") return;  // spdlog's default text lines
  auto formatter = std::make_unique<spdlog::pattern_formatter>();
  formatter->add_flag<JsonFields>('*').set_pattern(
      R"({"time":"%Y-%m-%dT%H:%M:%S.%e%z","level":"%l","thread":%t,%*})");
  spdlog::set_formatter(std::move(formatter));
}

}  // namespace downpour::app
