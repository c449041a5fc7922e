// The map family of CoveragePlanner calls: PutMap (decode, check and store a
// map; its decoding runs on the I/O pool), GetMap and DeleteMap (on the read
// pool, never behind decoding), ListMaps (paged, from the store's in-memory
// index, on the gRPC thread). Each call passes the CallGate once; another
// tenant's map answers as a missing one. A tenant with a max_maps quota
// stores no more new maps than that (on this replica's view of the store).
//
//   MapHandlers maps(options, store, &cache, metrics, &gate, &admission, &quotas, &io_pool,
//                    &read_pool);
//   return maps.GetMap(context, request, response);  // from the service's override
//
// Thread-safety: handlers are called concurrently by gRPC; they share only
// thread-safe parts.
#ifndef COVPLAN_SERVER_MAP_HANDLERS_H_
#define COVPLAN_SERVER_MAP_HANDLERS_H_

#include <functional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "server/admission.h"
#include "server/artifact_lru.h"
#include "server/call_gate.h"
#include "server/map_repository.h"
#include "server/metrics.h"
#include "server/service_options.h"
#include "server/tenant_quotas.h"
#include "server/worker_pool.h"

namespace covplan {

class MapHandlers {
 public:
  // Every pointer outlives this.
  MapHandlers(const ServiceOptions& options, MapRepository* store, ArtifactLru* cache,
              ServerMetrics* metrics, CallGate* gate, SolveAdmission* admission,
              const TenantQuotas* quotas, WorkerPool* io_pool, WorkerPool* read_pool);

  grpc::ServerUnaryReactor* PutMap(grpc::CallbackServerContext* context,
                                   const v1::PutMapRequest* request, v1::PutMapResponse* response);
  grpc::ServerUnaryReactor* GetMap(grpc::CallbackServerContext* context,
                                   const v1::GetMapRequest* request, v1::GetMapResponse* response);
  grpc::ServerUnaryReactor* ListMaps(grpc::CallbackServerContext* context,
                                     const v1::ListMapsRequest* request,
                                     v1::ListMapsResponse* response);
  grpc::ServerUnaryReactor* DeleteMap(grpc::CallbackServerContext* context,
                                      const v1::DeleteMapRequest* request,
                                      v1::DeleteMapResponse* response);

 private:
  // Runs `work` on `pool` and finishes the call with its status and the
  // detail it sets; work whose caller gave up while it was queued is dropped
  // unstarted. `trim`: memory is trimmed after a long call.
  void Serve(WorkerPool* pool, CancellableReactor* reactor, const CallInfo& call,
             std::function<absl::Status(std::string* detail)> work, bool trim);
  absl::Status RunPutMap(const v1::PutMapRequest& request, const CallInfo& call,
                         v1::PutMapResponse* response);
  // store_->Put, refused with RESOURCE_EXHAUSTED when `map_id` is a new map
  // of a tenant that already stores its max_maps.
  absl::StatusOr<bool> PutWithinQuota(const CallInfo& call, const v1::MapInfo& info,
                                      const v1::Map& map);
  absl::Status RunGetMap(const CallInfo& call, const v1::GetMapRequest& request,
                         v1::GetMapResponse* response);
  absl::Status RunListMaps(const CallInfo& call, const v1::ListMapsRequest& request,
                           v1::ListMapsResponse* response);
  // Keeps of `page` (and `corrupted`) only the tenant's maps, reading
  // further pages until `page_size` are found or the store has no more.
  absl::Status KeepTenantMaps(const std::string& tenant_tag, int page_size,
                              std::vector<v1::MapInfo>* page, bool* more,
                              std::vector<std::string>* corrupted);

  const ServiceOptions& options_;
  MapRepository* const store_;
  ArtifactLru* const cache_;
  ServerMetrics* const metrics_;
  CallGate* const gate_;
  SolveAdmission* const admission_;
  const TenantQuotas* const quotas_;
  // Held from counting a tenant's maps to storing its new one, for tenants
  // with a max_maps quota.
  absl::Mutex maps_quota_mu_;
  WorkerPool* const io_pool_;
  WorkerPool* const read_pool_;
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_MAP_HANDLERS_H_
