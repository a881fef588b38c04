#include "server/session/session_registry.hpp"

#include <cstdio>
#include <random>

namespace downpour::session {

SessionRegistry::SessionRegistry(int max_sessions, std::function<void()> wake_renderer)
    : max_sessions_(max_sessions), wake_renderer_(std::move(wake_renderer)) {
  std::random_device rd;
  id_salt_ = (static_cast<std::uint64_t>(rd()) << 32) ^ rd();
}

std::shared_ptr<Session> SessionRegistry::create(SessionConfig config, const sim::Update& initial) {
  std::shared_ptr<Session> session;
  {
    std::lock_guard lock(mutex_);
    if (static_cast<int>(sessions_.size()) >= max_sessions_) return nullptr;
    const std::uint64_t number = next_number_++;
    // splitmix64 of the salted number: unique per number, not guessable from it.
    std::uint64_t z = id_salt_ + number * 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    char id[32];
    std::snprintf(id, sizeof(id), "s%llu-%08llx", static_cast<unsigned long long>(number),
                  static_cast<unsigned long long>(z & 0xffffffffULL));
    session = std::make_shared<Session>(id, number, std::move(config), initial, wake_renderer_);
    sessions_.emplace(session->id(), session);
  }
  wake_renderer_();
  return session;
}

std::shared_ptr<Session> SessionRegistry::find(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it = sessions_.find(id);
  return it == sessions_.end() ? nullptr : it->second;
}

bool SessionRegistry::close(const std::string& id) {
  std::shared_ptr<Session> session;
  {
    std::lock_guard lock(mutex_);
    const auto it = sessions_.find(id);
    if (it == sessions_.end()) return false;
    session = std::move(it->second);
    sessions_.erase(it);
  }
  session->close();
  return true;
}

void SessionRegistry::close_all() {
  std::map<std::string, std::shared_ptr<Session>> sessions;
  {
    std::lock_guard lock(mutex_);
    sessions.swap(sessions_);
  }
  for (auto& [id, s] : sessions) s->close();
}

std::vector<std::shared_ptr<Session>> SessionRegistry::list() const {
  std::lock_guard lock(mutex_);
  std::vector<std::shared_ptr<Session>> out;
  out.reserve(sessions_.size());
  for (const auto& [id, s] : sessions_) out.push_back(s);
  return out;
}

}  // namespace downpour::session
