#include "server/served_replies.h"

#include <vector>

#include <grpcpp/impl/codegen/proto_utils.h>
#include <grpcpp/support/slice.h>

#include "absl/hash/hash.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace covplan {

std::string PlanSummary(const v1::PlanResponse& response) {
  return absl::StrFormat("planner=%s ranks=%d termination=%s/%s source=%s", response.planner(),
                         response.stats().num_ranks(),
                         v1::TerminationReason_Name(response.termination().reason()),
                         v1::TerminationLimit_Name(response.termination().limit()),
                         v1::PlanSource_Name(response.stats().plan_source()));
}

std::string PlanDetail(const v1::PlanResponse& response) {
  return absl::StrCat("plan=", response.plan_id(), " ", PlanSummary(response));
}

std::shared_ptr<const ServedBody> ServedBodyFor(const v1::PlanResponse& reply) {
  // The per-call fields are cleared: proto3 does not write a zero, so a
  // zero in the call's appended stats would not override a stored value.
  // Every call has its own plan id, in the appended part.
  v1::PlanResponse stored = reply;
  stored.clear_plan_id();
  stored.mutable_stats()->clear_planning_ms();
  stored.mutable_stats()->clear_decomposition_cached();
  auto body = std::make_shared<ServedBody>();
  if (!stored.SerializeToString(&body->bytes)) return nullptr;
  body->detail = PlanSummary(stored);
  return body;
}

absl::Status SerializePlanReply(const v1::PlanResponse& response,
                                std::shared_ptr<const ServedBody> served, grpc::ByteBuffer* out) {
  grpc::ByteBuffer tail;
  bool own = false;
  if (!grpc::SerializationTraits<v1::PlanResponse>::Serialize(response, &tail, &own).ok()) {
    return absl::InternalError("could not serialise the plan reply");
  }
  if (served == nullptr) {
    out->Swap(&tail);
    return absl::OkStatus();
  }
  std::vector<grpc::Slice> slices;
  if (!tail.Dump(&slices).ok()) return absl::InternalError("could not serialise the plan reply");
  using Body = std::shared_ptr<const ServedBody>;
  const std::string& bytes = served->bytes;
  auto* keep = new Body(std::move(served));  // released with the slice
  slices.insert(slices.begin(), grpc::Slice(
                                    const_cast<char*>(bytes.data()), bytes.size(),
                                    [](void* p) { delete static_cast<Body*>(p); }, keep));
  grpc::ByteBuffer whole(slices.data(), slices.size());
  out->Swap(&whole);
  return absl::OkStatus();
}

std::optional<ServedReplies::Served> ServedReplies::Find(
    const std::string& tenant_tag, const std::shared_ptr<const RememberedPlan>& entry) {
  absl::MutexLock lock(&mu_);
  auto it = served_.find(ServedHitKey(tenant_tag, entry.get()));
  if (it == served_.end() || it->second.entry.lock() != entry) return std::nullopt;
  return Served{it->second.reply, it->second.plan_id};
}

void ServedReplies::Remember(const std::string& tenant_tag, const EngineResult& hit,
                             const v1::PlanResponse& reply) {
  ServedHit served;
  served.entry = hit.answered_by;
  served.plan_id = reply.plan_id();
  served.bytes = reply.ByteSizeLong();
  if (served.bytes > kMaxServedHitBytes / 4) return;  // huge plans: converted per call
  served.reply = ServedBodyFor(reply);
  if (served.reply == nullptr) return;
  const ServedHitKey key(tenant_tag, hit.answered_by.get());
  absl::MutexLock lock(&mu_);
  auto [it, inserted] = served_.try_emplace(key);
  if (!inserted) {
    served_bytes_ -= it->second.bytes;
  } else {
    served_order_.push_back(key);
  }
  served_bytes_ += served.bytes;
  it->second = std::move(served);
  // Over a bound: drop the oldest keys (a key replaced in place keeps its place).
  while ((served_.size() > kMaxServedHits || served_bytes_ > kMaxServedHitBytes) &&
         !served_order_.empty()) {
    auto old = served_.find(served_order_.front());
    served_order_.pop_front();
    if (old == served_.end()) continue;
    served_bytes_ -= old->second.bytes;
    served_.erase(old);
  }
}

std::optional<uint64_t> ServedReplies::HitKey(const std::string& tenant_tag,
                                              const v1::PlanRequest& request,
                                              const grpc::ByteBuffer& request_bytes) {
  if (request.map_ref_case() != v1::PlanRequest::kMapId ||
      request_bytes.Length() > kMaxHitRequestBytes) {
    return std::nullopt;
  }
  std::vector<grpc::Slice> slices;
  if (!request_bytes.Dump(&slices).ok()) return std::nullopt;
  std::string bytes = tenant_tag;
  bytes.push_back('\n');
  for (const grpc::Slice& slice : slices) {
    bytes.append(reinterpret_cast<const char*>(slice.begin()), slice.size());
  }
  return absl::HashOf(bytes);
}

bool ServedReplies::IsHitRequest(uint64_t key) {
  absl::MutexLock lock(&mu_);
  return hit_requests_.contains(key);
}

void ServedReplies::NoteHitRequest(uint64_t key, bool hit) {
  absl::MutexLock lock(&mu_);
  if (!hit) {
    hit_requests_.erase(key);
    return;
  }
  if (hit_requests_.size() >= kMaxHitRequests) hit_requests_.clear();
  hit_requests_.insert(key);
}

}  // namespace covplan
