// The log's format (--log-format): spdlog's text lines, or one JSON object per line for log
// collectors: {"time", "level", "session" (on a session's lines), "msg"}.
#pragma once

#include <string>
#include <string_view>

namespace downpour::app {

// Sets the default logger's format: "text" or "json".
void set_log_format(const std::string& format);

// A line's JSON fields after "level" (tests): "session" when the message names one the way the
// server's session lines start ("session <id> ..." or "session <id>: ..."), then "msg"; escaped.
std::string json_log_fields(std::string_view message);

}  // namespace downpour::app
