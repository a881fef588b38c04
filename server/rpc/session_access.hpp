// What the service's calls on a session share: reaching the session (it exists, and the caller
// may drive or watch it), the statuses a step or a stream ends with, and the count of steps in
// flight that the drain waits for. Used by downpour_service.cpp and the two stream reactors
// (drive_reactor.cpp, watch_reactor.cpp).
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <utility>

#include <grpcpp/support/status.h>

#include "server/rpc/auth.hpp"
#include "server/session/session_registry.hpp"

namespace downpour::rpc {

grpc::Status not_found(const std::string& id);

// Access to a session (auth.hpp): its owner drives, watches and closes it; an admin any session;
// a viewer watches any. Anyone else gets PERMISSION_DENIED.
grpc::Status may_drive(const Principal& who, const session::Session& s);
grpc::Status may_watch(const Principal& who, const session::Session& s);

// The session that `id` (already checked) names, where `who` may reach it as `access` says
// (may_drive, may_watch): NOT_FOUND where there is none, or access's refusal.
grpc::Status reach_session(const session::SessionRegistry& registry, const std::string& id,
                           const Principal& who,
                           grpc::Status (*access)(const Principal&, const session::Session&),
                           std::shared_ptr<session::Session>* session);

// New sessions and steps while the server drains.
extern const grpc::Status kDraining;

// The status a stream ends with when its session ends: a normal end is OK.
grpc::Status stream_end_status(const session::SessionEnd& end);
// The status of a step that was accepted and then not rendered.
grpc::Status step_failure_status(const session::StepOutcome& o);
// The status of a request the session's queue refused (kQueued: OK).
grpc::Status submit_status(session::Session::Submit result, const std::string& id);

// Counts a step from its acceptance to its answer (the drain waits for these).
class StepInFlight {
 public:
  explicit StepInFlight(std::atomic<int>& count) : count_(&count) { ++*count_; }
  StepInFlight(StepInFlight&& other) noexcept : count_(std::exchange(other.count_, nullptr)) {}
  StepInFlight(const StepInFlight&) = delete;
  StepInFlight& operator=(const StepInFlight&) = delete;
  StepInFlight& operator=(StepInFlight&&) = delete;
  ~StepInFlight() {
    if (count_) --*count_;
  }

 private:
  std::atomic<int>* count_;
};

}  // namespace downpour::rpc
