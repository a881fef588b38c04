#include "server/rpc/session_access.hpp"

namespace downpour::rpc {

using session::Session;

grpc::Status not_found(const std::string& id) {
  return grpc::Status(grpc::StatusCode::NOT_FOUND, "session_id: no session '" + id + "'");
}

grpc::Status may_drive(const Principal& who, const Session& s) {
  if (who.has(kAdmin) || (who.has(kDriver) && who.name == s.config().owner))
    return grpc::Status::OK;
  if (who.name == s.config().owner) {
    return grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                        "'" + who.name + "' no longer has the driver role");
  }
  return grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                      "session " + s.id() + " belongs to another client; '" + who.name +
                          "' may only watch it with the viewer role");
}

grpc::Status may_watch(const Principal& who, const Session& s) {
  if (who.has(kViewer) || who.name == s.config().owner) return grpc::Status::OK;
  return grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                      "session " + s.id() +
                          " belongs to another client; watching it needs the "
                          "viewer role");
}

grpc::Status reach_session(const session::SessionRegistry& registry, const std::string& id,
                           const Principal& who,
                           grpc::Status (*access)(const Principal&, const Session&),
                           std::shared_ptr<Session>* session) {
  *session = registry.find(id);
  if (!*session) return not_found(id);
  return access(who, **session);
}

const grpc::Status kDraining(grpc::StatusCode::UNAVAILABLE,
                             "server shutting down: it takes no new sessions or steps");

grpc::Status stream_end_status(const session::SessionEnd& end) {
  switch (end.reason) {
    case session::EndReason::kClosed:
    case session::EndReason::kIdle:
      return grpc::Status::OK;
    case session::EndReason::kFailed:
      return grpc::Status(grpc::StatusCode::INTERNAL, end.message);
    case session::EndReason::kShuttingDown:
      return grpc::Status(grpc::StatusCode::UNAVAILABLE, end.message);
    case session::EndReason::kCancelled:
      return grpc::Status(grpc::StatusCode::CANCELLED, end.message);
  }
  return grpc::Status(grpc::StatusCode::INTERNAL, "unknown session end");
}

grpc::Status step_failure_status(const session::StepOutcome& o) {
  switch (o.failure) {
    case session::EndReason::kClosed:
    case session::EndReason::kIdle:
      return grpc::Status(grpc::StatusCode::ABORTED, o.error);
    case session::EndReason::kFailed:
      return grpc::Status(grpc::StatusCode::INTERNAL, o.error);
    case session::EndReason::kShuttingDown:
      return grpc::Status(grpc::StatusCode::UNAVAILABLE, o.error);
    case session::EndReason::kCancelled:
      return grpc::Status(grpc::StatusCode::CANCELLED, o.error);
  }
  return grpc::Status(grpc::StatusCode::INTERNAL, o.error);
}

grpc::Status submit_status(Session::Submit result, const std::string& id) {
  switch (result) {
    case Session::Submit::kQueued:
      return grpc::Status::OK;
    case Session::Submit::kFull:
      return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                          "session " + id + ": more than " +
                              std::to_string(Session::kMaxQueuedJobs) +
                              " requests waiting; wait for frames before sending more");
    case Session::Submit::kClosed:
      return grpc::Status(grpc::StatusCode::ABORTED, "session " + id + " was closed");
  }
  return grpc::Status(grpc::StatusCode::INTERNAL, "unexpected submit result");
}

}  // namespace downpour::rpc
