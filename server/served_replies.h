// The replies of repeated identical Plan hits. Identical requests answered
// from memory after the first such answer share its content, not its
// identity: each call is a mission of its own under a fresh plan id (an
// alias of the first hit's retained plan, PlanArchive::PutAlias), and its
// reply is the first hit's stored bytes, so a repeated hit sends stored
// bytes instead of a conversion, and neither copies the plan nor pushes
// other clients' plans out of the retained ones. Plan is a raw gRPC method:
// such a hit is sent as the first hit's serialised bytes (ServedBody, plan
// id cleared), followed by a short PlanResponse holding only this call's
// plan id and per-call stats; protobuf merges concatenated messages, so
// every client reads one reply, and no protobuf message is copied per hit.
//
// Beside them, the keys (a hash of the tenant and the request bytes) of the
// requests answered from memory last time: a repeat of one is expected to
// be a hit again (priced as one by the admission, tried on the gRPC thread
// first).
//
//   if (std::optional<ServedReplies::Served> s = served.Find(tenant, entry)) ...
//   served.Remember(tenant, result, reply);
//   SerializePlanReply(call_reply, s->reply, &bytes);
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_SERVED_REPLIES_H_
#define COVPLAN_SERVER_SERVED_REPLIES_H_

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include <grpcpp/support/byte_buffer.h>

#include "absl/base/thread_annotations.h"
#include "absl/container/flat_hash_set.h"
#include "absl/status/status.h"
#include "absl/synchronization/mutex.h"
#include "covplan/v1/covplan.pb.h"
#include "planner/engine/engine.h"
#include "planner/engine/plan_memory.h"

namespace covplan {

// A repeated hit's reply, serialised once: the reply with plan_id,
// planning_ms and decomposition_cached cleared, and its log summary.
struct ServedBody {
  std::string bytes;
  std::string detail;  // PlanSummary of the reply
};

// A Plan reply's log summary: "plan=<id> " and its PlanSummary.
std::string PlanDetail(const v1::PlanResponse& response);
// The summary without the plan id and the per-call decomposition_cached.
std::string PlanSummary(const v1::PlanResponse& response);

// A repeated hit's stored reply: `reply` serialised with its plan id and the
// per-call stats fields (planning_ms, decomposition_cached) cleared, so that
// the call's own values, written after it by SerializePlanReply, win even
// when they are zero or false; null if it cannot be serialised.
std::shared_ptr<const ServedBody> ServedBodyFor(const v1::PlanResponse& reply);

// A Plan reply's bytes: `response`'s, after those of `served` if set (a
// repeated hit, whose stored bytes are shared with the slice, not copied).
absl::Status SerializePlanReply(const v1::PlanResponse& response,
                                std::shared_ptr<const ServedBody> served, grpc::ByteBuffer* out);

class ServedReplies {
 public:
  struct Served {
    std::shared_ptr<const ServedBody> reply;
    std::string plan_id;  // the first hit's, valid while that plan is retained
  };
  // The reply already sent for the remembered `entry` to this tenant, if any.
  std::optional<Served> Find(const std::string& tenant_tag,
                             const std::shared_ptr<const RememberedPlan>& entry);
  // Records the reply of a hit (`hit.answered_by` set) for the next ones.
  void Remember(const std::string& tenant_tag, const EngineResult& hit,
                const v1::PlanResponse& reply);

  // The key of a Plan request by map id whose bytes are small enough to be
  // keyed; none otherwise (inline maps are never keyed).
  static std::optional<uint64_t> HitKey(const std::string& tenant_tag,
                                        const v1::PlanRequest& request,
                                        const grpc::ByteBuffer& request_bytes);
  // Whether the request with this key was answered from memory last time,
  // and recording whether it was.
  bool IsHitRequest(uint64_t key);
  void NoteHitRequest(uint64_t key, bool hit);

 private:
  // Keyed by tenant and remembered entry; the weak pointer tells a live
  // entry from a new one at a reused address. Bounded by count and bytes.
  struct ServedHit {
    std::weak_ptr<const RememberedPlan> entry;
    std::string plan_id;
    std::shared_ptr<const ServedBody> reply;
    size_t bytes = 0;
  };
  using ServedHitKey = std::pair<std::string, const RememberedPlan*>;
  static constexpr size_t kMaxServedHits = 64;
  static constexpr size_t kMaxServedHitBytes = size_t{16} << 20;
  static constexpr size_t kMaxHitRequests = 4096;      // then forgotten at once
  static constexpr size_t kMaxHitRequestBytes = 4096;  // larger requests are not keyed

  absl::Mutex mu_;
  std::map<ServedHitKey, ServedHit> served_ ABSL_GUARDED_BY(mu_);
  std::deque<ServedHitKey> served_order_ ABSL_GUARDED_BY(mu_);  // oldest first
  size_t served_bytes_ ABSL_GUARDED_BY(mu_) = 0;
  absl::flat_hash_set<uint64_t> hit_requests_ ABSL_GUARDED_BY(mu_);
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_SERVED_REPLIES_H_
