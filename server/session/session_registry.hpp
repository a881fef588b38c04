// The live sessions, by id, with the server's limits: a number of sessions and (admission.hpp)
// budgets of pixel rate and memory.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "server/session/admission.hpp"
#include "server/session/session.hpp"

namespace downpour::session {

class SessionRegistry {
 public:
  SessionRegistry(int max_sessions, std::function<void()> wake_renderer);

  // Null when a limit is reached; *refusal (if given) then says which. Ids are "s<number>-" and
  // 128 random bits in hex: no id can be guessed from others.
  std::shared_ptr<Session> create(SessionConfig config, const sim::Update& initial,
                                  std::string* refusal = nullptr);
  void set_budget(const AdmissionBudget& budget);
  AdmissionBudget budget() const;
  // The estimated cost of the live sessions together.
  SessionCost cost_in_use() const;
  std::shared_ptr<Session> find(const std::string& id) const;
  // Sessions that hear nothing from any client (no request, no stream attached) for this long
  // are closed by close_idle(); 0 = never.
  void set_idle_timeout_s(double seconds) { idle_timeout_s_ = seconds; }
  double idle_timeout_s() const { return idle_timeout_s_; }
  // Closes the sessions idle past the timeout; returns them (for the log).
  std::vector<std::shared_ptr<Session>> close_idle(Clock::time_point now);
  std::uint64_t closed_idle() const { return closed_idle_; }
  // Removes and closes; false for an unknown id.
  bool close(const std::string& id, const SessionEnd& end = {});
  void close_all(const SessionEnd& end = {});
  std::vector<std::shared_ptr<Session>> list() const;
  int max_sessions() const { return max_sessions_; }

 private:
  SessionCost cost_locked() const;  // mutex_ held

  const int max_sessions_;
  std::atomic<double> idle_timeout_s_{0.0};
  std::atomic<std::uint64_t> closed_idle_{0};
  const std::function<void()> wake_renderer_;
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Session>> sessions_;  // guarded by mutex_
  AdmissionBudget budget_;                                    // guarded by mutex_
  std::uint64_t next_number_ = 1;                             // guarded by mutex_
};

}  // namespace downpour::session
