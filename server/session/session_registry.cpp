#include "server/session/session_registry.hpp"

#include <sys/random.h>

#include <array>
#include <cerrno>
#include <string>
#include <system_error>

namespace downpour::session {

namespace {

// 128 bits from the kernel's random source (getrandom: never predictable from earlier output),
// as 32 hex digits.
std::string random_hex128() {
  std::array<unsigned char, 16> bytes{};
  std::size_t got = 0;
  while (got < bytes.size()) {
    const ssize_t n = getrandom(bytes.data() + got, bytes.size() - got, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::system_error(errno, std::generic_category(), "getrandom");
    }
    got += static_cast<std::size_t>(n);
  }
  std::string hex;
  hex.reserve(32);
  static constexpr char kDigits[] = "0123456789abcdef";
  for (unsigned char b : bytes) {
    hex += kDigits[b >> 4];
    hex += kDigits[b & 15];
  }
  return hex;
}

}  // namespace

SessionRegistry::SessionRegistry(int max_sessions, std::function<void()> wake_renderer)
    : max_sessions_(max_sessions), wake_renderer_(std::move(wake_renderer)) {}

std::shared_ptr<Session> SessionRegistry::create(SessionConfig config, const sim::Update& initial,
                                                 std::string* refusal) {
  std::shared_ptr<Session> session;
  {
    std::lock_guard lock(mutex_);
    if (static_cast<int>(sessions_.size()) >= max_sessions_) {
      if (refusal) {
        *refusal = "sessions: the server's limit of " + std::to_string(max_sessions_) +
                   " sessions is reached (--max-sessions); close one first";
      }
      return nullptr;
    }
    if (std::string why = admission_refusal(budget_, cost_locked(), estimate_cost(config));
        !why.empty()) {
      if (refusal) *refusal = std::move(why);
      return nullptr;
    }
    const std::uint64_t number = next_number_++;
    // The number for people reading logs; 128 random bits so that no one can guess an id.
    std::string id = "s";
    id += std::to_string(number);
    id += '-';
    id += random_hex128();
    session = std::make_shared<Session>(id, number, std::move(config), initial, wake_renderer_);
    sessions_.emplace(session->id(), session);
  }
  wake_renderer_();
  return session;
}

void SessionRegistry::set_budget(const AdmissionBudget& budget) {
  std::lock_guard lock(mutex_);
  budget_ = budget;
}

AdmissionBudget SessionRegistry::budget() const {
  std::lock_guard lock(mutex_);
  return budget_;
}

SessionCost SessionRegistry::cost_in_use() const {
  std::lock_guard lock(mutex_);
  return cost_locked();
}

SessionCost SessionRegistry::cost_locked() const {
  SessionCost used;
  for (const auto& [id, s] : sessions_) {
    const SessionCost c = estimate_cost(s->config());
    used.pixel_rate += c.pixel_rate;
    used.memory_bytes += c.memory_bytes;
  }
  return used;
}

std::vector<std::shared_ptr<Session>> SessionRegistry::close_idle(Clock::time_point now) {
  std::vector<std::shared_ptr<Session>> idle;
  const double timeout = idle_timeout_s_;
  if (timeout <= 0.0) return idle;
  {
    std::lock_guard lock(mutex_);
    for (auto it = sessions_.begin(); it != sessions_.end();) {
      if (it->second->idle_s(now) <= timeout) {
        ++it;
        continue;
      }
      idle.push_back(it->second);
      it = sessions_.erase(it);
      ++closed_idle_;
    }
  }
  for (const auto& s : idle) {
    s->close({EndReason::kIdle, "session " + s->id() + " was closed: no client was heard for " +
                                    std::to_string(static_cast<int>(timeout)) + " s"});
  }
  return idle;
}

std::shared_ptr<Session> SessionRegistry::find(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it = sessions_.find(id);
  return it == sessions_.end() ? nullptr : it->second;
}

bool SessionRegistry::close(const std::string& id, const SessionEnd& end) {
  std::shared_ptr<Session> session;
  {
    std::lock_guard lock(mutex_);
    const auto it = sessions_.find(id);
    if (it == sessions_.end()) return false;
    session = std::move(it->second);
    sessions_.erase(it);
  }
  session->close(end);
  return true;
}

void SessionRegistry::close_all(const SessionEnd& end) {
  std::map<std::string, std::shared_ptr<Session>> sessions;
  {
    std::lock_guard lock(mutex_);
    sessions.swap(sessions_);
  }
  for (auto& [id, s] : sessions) s->close(end);
}

std::vector<std::shared_ptr<Session>> SessionRegistry::list() const {
  std::lock_guard lock(mutex_);
  std::vector<std::shared_ptr<Session>> out;
  out.reserve(sessions_.size());
  for (const auto& [id, s] : sessions_) out.push_back(s);
  return out;
}

}  // namespace downpour::session
