#include "server/live_events.h"

#include <google/protobuf/util/json_util.h>

#include <utility>

namespace covplan {

LiveEvents::Subscription::~Subscription() { hub_->Remove(this); }

LiveEvents::Batch LiveEvents::Subscription::Next(absl::Duration timeout) {
  Batch out;
  const absl::Time deadline = absl::Now() + timeout;
  absl::MutexLock lock(&hub_->mu_);
  while (queue_.empty() && !hub_->closed_) {
    if (hub_->changed_.WaitWithDeadline(&hub_->mu_, deadline)) break;  // timed out
  }
  out.events.assign(std::make_move_iterator(queue_.begin()), std::make_move_iterator(queue_.end()));
  queue_.clear();
  out.dropped = dropped_;
  dropped_ = 0;
  out.closed = hub_->closed_;
  return out;
}

std::shared_ptr<LiveEvents::Subscription> LiveEvents::Subscribe(const std::string& map_id) {
  absl::MutexLock lock(&mu_);
  if (closed_ || by_map_.size() >= max_subscribers_) return nullptr;
  std::shared_ptr<Subscription> s(new Subscription(this, map_id));
  by_map_.emplace(map_id, s.get());
  return s;
}

bool LiveEvents::Watched(const std::string& map_id) const {
  absl::MutexLock lock(&mu_);
  return by_map_.count(map_id) > 0;
}

void LiveEvents::Publish(const v1::LiveEvent& event) {
  if (!Watched(event.map_id())) return;
  std::string json;
  if (!google::protobuf::util::MessageToJsonString(event, &json).ok()) return;
  absl::MutexLock lock(&mu_);
  const auto [first, last] = by_map_.equal_range(event.map_id());
  for (auto it = first; it != last; ++it) {
    Subscription* s = it->second;
    s->queue_.push_back(json);
    while (s->queue_.size() > queue_limit_) {
      s->queue_.pop_front();
      ++s->dropped_;
    }
  }
  changed_.SignalAll();
}

void LiveEvents::Close() {
  absl::MutexLock lock(&mu_);
  closed_ = true;
  changed_.SignalAll();
}

size_t LiveEvents::subscribers() const {
  absl::MutexLock lock(&mu_);
  return by_map_.size();
}

void LiveEvents::Remove(Subscription* s) {
  absl::MutexLock lock(&mu_);
  const auto [first, last] = by_map_.equal_range(s->map_id_);
  for (auto it = first; it != last; ++it) {
    if (it->second == s) {
      by_map_.erase(it);
      return;
    }
  }
}

}  // namespace covplan
