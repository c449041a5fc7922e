// What the robots on a map do, as it happens, for whoever watches that map:
// Drive sessions publish LiveEvents (a session opened, progress, obstacles
// reported, a new plan, the session ended) and the JSON API's event stream
// (GET /v1/events?map_id=..., server/http_gateway.h) subscribes per map.
// Map ids carry their tenant (server/tenant_tokens.h), so a subscriber who
// may read the map sees only its own tenant's robots.
//
//   LiveEvents live(/*max_subscribers=*/4, /*queue_limit=*/1024);
//   std::shared_ptr<LiveEvents::Subscription> s = live.Subscribe(map_id);  // null: full
//   live.Publish(event);                        // from any thread; cheap when nobody listens
//   LiveEvents::Batch b = s->Next(absl::Seconds(15));  // JSON lines, or empty on timeout
//   live.Close();                               // every Next returns, closed = true
//
// A subscriber that falls behind loses its oldest events (Batch::dropped
// says how many), never the publisher's time.
//
// Thread-safety: all methods are thread-safe.
#ifndef COVPLAN_SERVER_LIVE_EVENTS_H_
#define COVPLAN_SERVER_LIVE_EVENTS_H_

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "covplan/v1/covplan.pb.h"

namespace covplan {

class LiveEvents {
 public:
  struct Batch {
    std::vector<std::string> events;  // each a LiveEvent in protobuf's JSON mapping
    int64_t dropped = 0;              // events lost since the last batch (the queue was full)
    bool closed = false;              // the hub closed: no more events
  };

  class Subscription {
   public:
    ~Subscription();
    // Waits up to `timeout` for events; returns what is queued.
    Batch Next(absl::Duration timeout);

   private:
    friend class LiveEvents;
    Subscription(LiveEvents* hub, std::string map_id) : hub_(hub), map_id_(std::move(map_id)) {}
    LiveEvents* const hub_;
    const std::string map_id_;
    std::deque<std::string> queue_ ABSL_GUARDED_BY(hub_->mu_);
    int64_t dropped_ ABSL_GUARDED_BY(hub_->mu_) = 0;
  };

  LiveEvents(size_t max_subscribers, size_t queue_limit)
      : max_subscribers_(max_subscribers), queue_limit_(queue_limit) {}
  LiveEvents(const LiveEvents&) = delete;
  LiveEvents& operator=(const LiveEvents&) = delete;

  // Null when max_subscribers are subscribed already, or after Close. Every
  // subscription must end (be destroyed) before the hub.
  std::shared_ptr<Subscription> Subscribe(const std::string& map_id);
  // True when someone watches `map_id` (lets publishers skip building events).
  bool Watched(const std::string& map_id) const;
  // Queues `event` for the subscribers of its map_id.
  void Publish(const v1::LiveEvent& event);
  // Wakes every subscriber for good.
  void Close();
  size_t subscribers() const;

 private:
  void Remove(Subscription* s);

  const size_t max_subscribers_;
  const size_t queue_limit_;
  mutable absl::Mutex mu_;
  absl::CondVar changed_;
  bool closed_ ABSL_GUARDED_BY(mu_) = false;
  std::multimap<std::string, Subscription*> by_map_ ABSL_GUARDED_BY(mu_);
};

}  // namespace covplan

#endif  // COVPLAN_SERVER_LIVE_EVENTS_H_
