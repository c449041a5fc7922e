#include "server/map_handlers.h"

#include <algorithm>
#include <utility>

#include "absl/strings/str_cat.h"
#include "api/convert.h"
#include "planner/common/status_macros.h"
#include "planner/engine/site.h"
#include "server/not_found.h"
#include "server/request_limits.h"
#include "server/tenant_tokens.h"

namespace covplan {
namespace {

// Page sizes of ListMaps (AIP-158).
constexpr int kDefaultPageSize = 100;
constexpr int kMaxPageSize = 1000;

}  // namespace

MapHandlers::MapHandlers(const ServiceOptions& options, MapRepository* store, ArtifactLru* cache,
                         ServerMetrics* metrics, CallGate* gate, SolveAdmission* admission,
                         const TenantQuotas* quotas, WorkerPool* io_pool, WorkerPool* read_pool)
    : options_(options),
      store_(store),
      cache_(cache),
      metrics_(metrics),
      gate_(gate),
      admission_(admission),
      quotas_(quotas),
      io_pool_(io_pool),
      read_pool_(read_pool) {}

void MapHandlers::Serve(WorkerPool* pool, CancellableReactor* reactor, const CallInfo& call,
                        std::function<absl::Status(std::string* detail)> work, bool trim) {
  if (!pool->TrySubmit([this, reactor, call, work = std::move(work), trim] {
        std::string detail;
        absl::Status status = QueuedTooLong(call, reactor->cancel());
        if (status.ok()) status = work(&detail);
        gate_->Finish(reactor, call, status, detail);
        if (trim) admission_->TrimMemoryIfIdle(absl::Now() - call.start);
      })) {
    gate_->Finish(reactor, call, WorkQueueFull());
  }
}

absl::StatusOr<bool> MapHandlers::PutWithinQuota(const CallInfo& call, const v1::MapInfo& info,
                                                 const v1::Map& map) {
  const int64_t max_maps = quotas_->For(call.tenant_tag).max_maps;
  if (max_maps == 0) return store_->Put(info, map);
  absl::MutexLock lock(&maps_quota_mu_);
  int64_t stored = 0;
  for (const v1::MapInfo& other : store_->List(nullptr)) {
    if (other.map_id() == info.map_id()) return store_->Put(info, map);  // not a new map
    stored += OwnsMap(call.tenant_tag, other.map_id()) ? 1 : 0;
  }
  if (stored >= max_maps) {
    return absl::ResourceExhaustedError(absl::StrCat(
        call.tenant.empty() ? std::string("the caller") : absl::StrCat("tenant ", call.tenant),
        " stores ", stored, " maps, its quota of ", max_maps,
        " (--tenant_max_maps or its line in --tenant_quota_file); delete one first"));
  }
  return store_->Put(info, map);
}

absl::Status MapHandlers::RunPutMap(const v1::PutMapRequest& request, const CallInfo& call,
                                    v1::PutMapResponse* response) {
  ASSIGN_OR_RETURN(SiteMap site, SiteFromProto(request.map(), options_.limits));
  RETURN_IF_ERROR(CheckSiteGeometry(site));
  // Per tenant: the same content stored by two tenants is two maps.
  const std::string map_id = ScopedMapId(ComputeMapId(request.map()), call.tenant_tag);
  v1::MapInfo info = MapInfoFor(site, map_id);
  info.set_name(request.name());
  ASSIGN_OR_RETURN(bool created, PutWithinQuota(call, info, request.map()));
  // A rewritten (repaired) map must not be planned from artifacts of the
  // damaged copy; the content is the same, but be safe and cheap: drop them.
  if (created) cache_->EraseWithPrefix(map_id + "/");
  if (!created) {
    ASSIGN_OR_RETURN(v1::GetMapResponse stored, store_->Get(map_id));
    info = stored.info();
  }
  response->set_map_id(map_id);
  response->set_created(created);
  *response->mutable_info() = info;
  metrics_->maps_stored().Set(static_cast<double>(store_->size()));
  return absl::OkStatus();
}

grpc::ServerUnaryReactor* MapHandlers::PutMap(grpc::CallbackServerContext* context,
                                              const v1::PutMapRequest* request,
                                              v1::PutMapResponse* response) {
  auto* reactor = new CancellableReactor();
  CallInfo call;
  if (!gate_->Open(context, "PutMap", reactor, *request, WhileDraining::kRefuse, &call)) {
    return reactor;
  }
  Serve(
      io_pool_, reactor, call,
      [this, call, request, response](std::string* detail) {
        absl::Status status = RunPutMap(*request, call, response);
        *detail = response->map_id();
        return status;
      },
      /*trim=*/true);
  return reactor;
}

absl::Status MapHandlers::RunGetMap(const CallInfo& call, const v1::GetMapRequest& request,
                                    v1::GetMapResponse* response) {
  // Another tenant's map answers as a missing one.
  absl::StatusOr<v1::GetMapResponse> stored = MapNotFound(request.map_id());
  if (OwnsMap(call.tenant_tag, request.map_id()) || !ValidateMapId(request.map_id()).ok()) {
    stored = store_->Get(request.map_id());  // a malformed id: INVALID_ARGUMENT for all
  }
  if (absl::IsNotFound(stored.status())) stored = MapNotFound(request.map_id());
  if (absl::IsDataLoss(stored.status())) cache_->EraseWithPrefix(request.map_id() + "/");
  if (stored.ok()) {
    *response->mutable_info() = stored->info();
    if (request.include_content()) *response->mutable_map() = std::move(*stored->mutable_map());
  }
  return stored.status();
}

grpc::ServerUnaryReactor* MapHandlers::GetMap(grpc::CallbackServerContext* context,
                                              const v1::GetMapRequest* request,
                                              v1::GetMapResponse* response) {
  auto* reactor = new CancellableReactor();
  CallInfo call;
  if (!gate_->Open(context, "GetMap", reactor, *request, WhileDraining::kServe, &call)) {
    return reactor;
  }
  // On the read pool: never behind PutMap's decoding.
  Serve(
      read_pool_, reactor, call,
      [this, call, request, response](std::string* detail) {
        *detail = QuotePrefix(request->map_id());
        return RunGetMap(call, *request, response);
      },
      /*trim=*/false);
  return reactor;
}

absl::Status MapHandlers::KeepTenantMaps(const std::string& tenant_tag, int page_size,
                                         std::vector<v1::MapInfo>* page, bool* more,
                                         std::vector<std::string>* corrupted) {
  const auto foreign = [&](const std::string& id) { return !OwnsMap(tenant_tag, id); };
  corrupted->erase(std::remove_if(corrupted->begin(), corrupted->end(), foreign), corrupted->end());
  std::vector<v1::MapInfo> mine;
  while (true) {
    const std::string last = page->empty() ? "" : page->back().map_id();
    for (v1::MapInfo& info : *page) {
      if (!foreign(info.map_id())) mine.push_back(std::move(info));
    }
    if (!*more || static_cast<int>(mine.size()) >= page_size || last.empty()) break;
    absl::StatusOr<std::vector<v1::MapInfo>> next =
        store_->ListPage(last, page_size, more, nullptr);
    if (!next.ok()) return next.status();
    *page = std::move(*next);
  }
  if (static_cast<int>(mine.size()) > page_size) {
    mine.resize(page_size);
    *more = true;
  }
  *page = std::move(mine);
  return absl::OkStatus();
}

absl::Status MapHandlers::RunListMaps(const CallInfo& call, const v1::ListMapsRequest& request,
                                      v1::ListMapsResponse* response) {
  if (request.page_size() < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("page_size must be >= 0 (got ", request.page_size(), ")"));
  }
  // The token is the last map_id of the previous page (ids are sorted).
  const std::string& token = request.page_token();
  if (!token.empty() && !ValidateMapId(token).ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("page_token '", QuotePrefix(token), "' is not a next_page_token of ListMaps"));
  }
  const int page_size =
      request.page_size() == 0 ? kDefaultPageSize : std::min(request.page_size(), kMaxPageSize);
  std::vector<std::string> corrupted;  // in-memory index only: cheap
  bool more = false;
  ASSIGN_OR_RETURN(std::vector<v1::MapInfo> page,
                   store_->ListPage(token, page_size, &more, token.empty() ? &corrupted : nullptr));
  if (!call.tenant_tag.empty()) {
    // Only the caller's maps: keep reading pages until this one is full.
    RETURN_IF_ERROR(KeepTenantMaps(call.tenant_tag, page_size, &page, &more, &corrupted));
  }
  for (v1::MapInfo& info : page) {
    // Names are bounded at PutMap; older stores may hold longer ones.
    if (info.name().size() > kMapNameLimit) info.mutable_name()->resize(kMapNameLimit);
    *response->add_maps() = std::move(info);
  }
  if (corrupted.size() > static_cast<size_t>(kMaxPageSize)) corrupted.resize(kMaxPageSize);
  for (std::string& id : corrupted) response->add_corrupted(std::move(id));
  if (more && response->maps_size() > 0) {
    response->set_next_page_token(response->maps(response->maps_size() - 1).map_id());
  }
  return absl::OkStatus();
}

grpc::ServerUnaryReactor* MapHandlers::ListMaps(grpc::CallbackServerContext* context,
                                                const v1::ListMapsRequest* request,
                                                v1::ListMapsResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  CallInfo call;
  if (!gate_->Open(context, "ListMaps", reactor, *request, WhileDraining::kServe, &call)) {
    return reactor;
  }
  gate_->Finish(reactor, call, RunListMaps(call, *request, response));
  return reactor;
}

grpc::ServerUnaryReactor* MapHandlers::DeleteMap(grpc::CallbackServerContext* context,
                                                 const v1::DeleteMapRequest* request,
                                                 v1::DeleteMapResponse* response) {
  auto* reactor = new CancellableReactor();
  CallInfo call;
  if (!gate_->Open(context, "DeleteMap", reactor, *request, WhileDraining::kServe, &call)) {
    return reactor;
  }
  Serve(
      read_pool_, reactor, call,
      [this, call, request, response](std::string* detail) {
        // Another tenant's map answers as a missing one: nothing deleted.
        absl::StatusOr<bool> deleted = false;
        if (OwnsMap(call.tenant_tag, request->map_id()) || !ValidateMapId(request->map_id()).ok()) {
          deleted = store_->Delete(request->map_id());
        }
        if (deleted.ok()) {
          response->set_deleted(*deleted);
          cache_->EraseWithPrefix(request->map_id() + "/");
          metrics_->maps_stored().Set(static_cast<double>(store_->size()));
        }
        *detail = QuotePrefix(request->map_id());
        return deleted.status();
      },
      /*trim=*/false);
  return reactor;
}

}  // namespace covplan
