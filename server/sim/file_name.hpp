// What a client may name a file by (a map in --maps-dir, a model in --models-dir, a buffer beside
// a model): a plain name in one directory, never a path.
#pragma once

#include <cstddef>
#include <string_view>

namespace downpour::sim {

// Letters, digits, '_', '-' and '.'; not empty, not starting with '.', no "..", at most `max`.
inline bool plain_file_name(std::string_view name, std::size_t max = 128) {
  if (name.empty() || name.size() > max || name.front() == '.') return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return name.find("..") == std::string_view::npos;
}

}  // namespace downpour::sim
