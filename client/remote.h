// A small synchronous client of covplan.v1.CoveragePlanner, the only client
// unit that includes gRPC headers (each costs seconds to compile).
// gRPC errors come back as absl::Status with the same code and message.
// Every call carries the map it is about as `x-covplan-map-id` metadata (an
// inline map: its content hash), the key a map-affine router hashes on.
//
//   std::unique_ptr<RemotePlanner> remote = RemotePlanner::Connect("127.0.0.1:50051");
//   // or, with TLS and a bearer token (client/connection.h):
//   std::unique_ptr<RemotePlanner> remote = RemotePlanner::Connect(connection);
//   ASSIGN_OR_RETURN(v1::PutMapResponse put, remote->PutMap(request, absl::Seconds(30)));
//   ASSIGN_OR_RETURN(v1::PlanResponse plan, remote->Plan(plan_request, absl::Seconds(5)));
//
// Thread-safety: all methods may be called concurrently (gRPC stubs are).
#ifndef COVPLAN_CLIENT_REMOTE_H_
#define COVPLAN_CLIENT_REMOTE_H_

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "client/connection.h"
#include "covplan/v1/covplan.pb.h"

namespace grpc {
class Channel;
class ClientContext;
}  // namespace grpc

namespace covplan {

// A channel with the connection's transport security (plaintext, TLS or
// mutual TLS), and the per-call metadata it needs (the bearer token).
std::shared_ptr<grpc::Channel> ChannelFor(const Connection& connection);
// "server TARGET replied CODE: message", how the CLI reports a server's error.
std::string ServerError(const std::string& target, const absl::Status& status);
void AddCallCredentials(const Connection& connection, grpc::ClientContext* context);

class RemotePlanner {
  struct Impl;

 public:
  static std::unique_ptr<RemotePlanner> Connect(const std::string& target);  // plaintext, no token
  static std::unique_ptr<RemotePlanner> Connect(const Connection& connection);
  ~RemotePlanner();

  absl::StatusOr<v1::PutMapResponse> PutMap(const v1::PutMapRequest& request,
                                            absl::Duration timeout);
  // No timeout: the call has no deadline (the server's default budget applies).
  absl::StatusOr<v1::PlanResponse> Plan(const v1::PlanRequest& request,
                                        std::optional<absl::Duration> timeout);
  // The same call, for load generation: the reply's bytes are received in
  // full but only its stats are decoded (a plan reply of tens of kB would
  // otherwise cost the client more CPU than the server spends on a hit).
  absl::StatusOr<v1::PlanStats> PlanStatsOnly(const v1::PlanRequest& request,
                                              std::optional<absl::Duration> timeout);
  // `map_id` (optional) is sent as routing metadata for a replan by plan_id.
  absl::StatusOr<v1::ReplanResponse> Replan(const v1::ReplanRequest& request,
                                            std::optional<absl::Duration> timeout,
                                            const std::string& map_id = "");
  absl::StatusOr<v1::ReplanResponse> Resume(const v1::ResumeRequest& request,
                                            std::optional<absl::Duration> timeout);
  absl::StatusOr<v1::PlanFleetResponse> PlanFleet(const v1::PlanFleetRequest& request,
                                                  std::optional<absl::Duration> timeout);

  // A Drive session, driven synchronously: Open sends the first message and
  // waits for the ready event; Observe sends an observation and waits for the
  // event that answers it; Report sends progress only.
  //
  // The session outlives its server: when the stream breaks with
  // UNAVAILABLE (the replica died or drains, the link dropped) or UNKNOWN
  // (no status reached the client: a proxy ended it), the session
  // opens a new one on the same channel (a router sends it to a live
  // replica) with backoff, 100 ms doubling to 1 s (+-20 %), for up to
  // kReconnectBudget, as the protocol asks of a robot (docs/robustness.md):
  // the first message names the newest plan the session received (the
  // server stores a replan before it sends it), carries the latest progress
  // sent and the session's method and seed; then the observation that was
  // not answered is sent again (at most kMaxResends times). A reopened
  // stream refused as busy (RESOURCE_EXHAUSTED) is retried the same way.
  // Other errors end the session as before. A session must not outlive its
  // RemotePlanner.
  class DriveSession {
   public:
    static constexpr absl::Duration kReconnectBudget = absl::Seconds(30);
    // How often one observation is sent again on a new stream.
    static constexpr int kMaxResends = 4;
    ~DriveSession();  // cancels the call if Close was not called
    const v1::DriveReady& ready() const { return ready_; }
    absl::StatusOr<v1::DriveEvent> Observe(const v1::DriveRequest& request);
    absl::Status Report(const v1::DriveRequest& request);
    // Half-closes and returns the call's final status.
    absl::Status Close();
    // How long each reconnect took, from the break to the new ready event.
    const std::vector<double>& reconnect_seconds() const { return reconnect_s_; }

   private:
    friend class RemotePlanner;
    struct Stream;
    DriveSession(Impl* owner, const v1::DriveRequest& first, const std::string& map_id);
    // Opens a stream, sends `first` and reads its ready event.
    absl::Status Open(const v1::DriveRequest& first);
    // After a break: reopens with backoff while the answer is UNAVAILABLE.
    absl::Status Reconnect(absl::Status broken);
    // The stream's final status once Write or Read failed.
    absl::Status Broken();
    // One exchange on the current stream: the answer to `request`.
    absl::StatusOr<v1::DriveEvent> Exchange(const v1::DriveRequest& request);
    void Remember(const v1::DriveRequest& request);

    Impl* const owner_;         // opens the streams; outlives the session
    v1::DriveRequest first_;    // plan_id: the newest plan received
    const std::string map_id_;  // routing metadata of every stream
    std::unique_ptr<Stream> stream_;
    v1::DriveReady ready_;
    bool closed_ = false;
    std::vector<double> reconnect_s_;
  };
  // `map_id` (optional: the plan's map) is sent as routing metadata on the
  // session's streams, so a map-affine router sends the session to the
  // replica that planned on that map (the plan is in its memory).
  absl::StatusOr<std::unique_ptr<DriveSession>> Drive(const v1::DriveRequest& first,
                                                      const std::string& map_id = "");

 private:
  explicit RemotePlanner(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace covplan

#endif  // COVPLAN_CLIENT_REMOTE_H_
