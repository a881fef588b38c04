// The live sessions, by id, with the server's session limit.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "server/session/session.hpp"

namespace downpour::session {

class SessionRegistry {
 public:
  SessionRegistry(int max_sessions, std::function<void()> wake_renderer);

  // Null when the limit is reached.
  std::shared_ptr<Session> create(SessionConfig config, const sim::Update& initial);
  std::shared_ptr<Session> find(const std::string& id) const;
  // Removes and closes; false for an unknown id.
  bool close(const std::string& id);
  void close_all();
  std::vector<std::shared_ptr<Session>> list() const;
  int max_sessions() const { return max_sessions_; }

 private:
  const int max_sessions_;
  const std::function<void()> wake_renderer_;
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Session>> sessions_;  // guarded by mutex_
  std::uint64_t next_number_ = 1;                             // guarded by mutex_
  std::uint64_t id_salt_;  // random, so that ids are not guessable
};

}  // namespace downpour::session
