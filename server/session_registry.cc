#include <algorithm>
#include <string>
#include <vector>

#include "server/drive_session.h"

namespace covplan {

SessionRegistry::SessionRegistry(int max_sessions, absl::Duration idle_timeout)
    : max_sessions_(max_sessions), idle_timeout_(idle_timeout), reaper_([this] { Reap(); }) {}

SessionRegistry::~SessionRegistry() {
  {
    absl::MutexLock lock(&mu_);
    stop_ = true;
  }
  reaper_.join();
}

bool SessionRegistry::Add(DriveSession* session) {
  absl::MutexLock lock(&mu_);
  if (static_cast<int>(sessions_.size()) >= max_sessions_) return false;
  sessions_.insert(session);
  return true;
}

void SessionRegistry::Remove(DriveSession* session) {
  absl::MutexLock lock(&mu_);
  sessions_.erase(session);
  for (auto it = by_plan_.begin(); it != by_plan_.end();) {
    it = it->second == session ? by_plan_.erase(it) : std::next(it);
  }
}

DriveSession* SessionRegistry::Find(const std::string& plan_id) {
  absl::MutexLock lock(&mu_);
  auto it = by_plan_.find(plan_id);
  if (it == by_plan_.end()) return nullptr;
  it->second->Ref();
  return it->second;
}

void SessionRegistry::Track(DriveSession* session, const std::string& plan_id) {
  absl::MutexLock lock(&mu_);
  if (!sessions_.count(session)) return;  // removed (or never admitted)
  by_plan_[plan_id] = session;
}

void SessionRegistry::Untrack(DriveSession* session, const std::string& plan_id) {
  absl::MutexLock lock(&mu_);
  if (auto it = by_plan_.find(plan_id); it != by_plan_.end() && it->second == session) {
    by_plan_.erase(it);
  }
}

int SessionRegistry::size() const {
  absl::MutexLock lock(&mu_);
  return static_cast<int>(sessions_.size());
}

std::vector<DriveSession*> SessionRegistry::Snapshot() {
  absl::MutexLock lock(&mu_);
  std::vector<DriveSession*> out(sessions_.begin(), sessions_.end());
  for (DriveSession* s : out) s->Ref();  // kept alive while inspected
  return out;
}

void SessionRegistry::EndAll() {
  for (DriveSession* s : Snapshot()) {
    s->End(grpc::Status(grpc::StatusCode::UNAVAILABLE, "server is shutting down"));
    s->Unref();
  }
}

void SessionRegistry::Reap() {
  const absl::Duration tick = std::min(absl::Seconds(1), idle_timeout_ / 4);
  for (;;) {
    {
      absl::MutexLock lock(&mu_);
      if (mu_.AwaitWithTimeout(absl::Condition(&stop_), tick)) return;
    }
    const absl::Time idle_before = absl::Now() - idle_timeout_;
    for (DriveSession* s : Snapshot()) {
      s->ExpireIfIdle(idle_before);
      s->Unref();
    }
  }
}

}  // namespace covplan
