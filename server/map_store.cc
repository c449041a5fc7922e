#include "server/map_store.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/time/clock.h"
#include "api/convert.h"
#include "api/digest.h"
#include "server/log.h"

namespace covplan {
namespace {

constexpr char kMagic[] = "covplan-map 1";
constexpr char kSuffix[] = ".map";
constexpr char kLockName[] = ".lock";
constexpr char kProbeName[] = "write_probe.txt";

absl::Status LoadingError() {
  return absl::UnavailableError(
      "the map store is still being indexed after a restart; retry shortly");
}

// A failed file operation as the client sees it: what failed and why, never
// the server's paths (those go to the log). A full disk is
// RESOURCE_EXHAUSTED, a store that may not be written UNAVAILABLE.
absl::Status ErrnoError(absl::string_view what, const std::string& path) {
  const int err = errno;
  LogLine("error", "map store file operation failed",
          {{"op", std::string(what)}, {"path", path}, {"errno", std::strerror(err)}});
  if (err == ENOSPC || err == EDQUOT) {
    return absl::ResourceExhaustedError("map store is full (no space left on the server's disk)");
  }
  if (err == EROFS || err == EACCES || err == EPERM) {
    return absl::UnavailableError(
        absl::StrCat("map store is not writable (", std::strerror(err), ")"));
  }
  return absl::InternalError(absl::StrCat("map store: ", what, ": ", std::strerror(err)));
}

absl::Status WriteAll(int fd, absl::string_view data, const std::string& path) {
  while (!data.empty()) {
    const ssize_t n = ::write(fd, data.data(), data.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return ErrnoError("cannot write", path);
    }
    data.remove_prefix(static_cast<size_t>(n));
  }
  return absl::OkStatus();
}

absl::Status FsyncDir(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return ErrnoError("cannot open directory", dir);
  const int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) return ErrnoError("cannot fsync directory", dir);
  return absl::OkStatus();
}

// Writes `contents` to a new temporary file beside `path` (fsynced when
// `sync`) and returns its name; nothing is left behind on failure.
absl::StatusOr<std::string> WriteTemp(const std::string& path, absl::string_view contents,
                                      bool sync) {
  static std::atomic<uint64_t> counter{0};
  const std::string tmp =
      absl::StrCat(path, ".tmp.", ::getpid(), ".", counter.fetch_add(1, std::memory_order_relaxed));
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return ErrnoError("cannot create", tmp);
  absl::Status status = WriteAll(fd, contents, tmp);
  if (sync && status.ok() && ::fsync(fd) != 0) status = ErrnoError("cannot fsync", tmp);
  if (::close(fd) != 0 && status.ok()) status = ErrnoError("cannot close", tmp);
  if (!status.ok()) {
    ::unlink(tmp.c_str());
    return status;
  }
  return tmp;
}

// Writes `contents` to `path` atomically: temp file, fsync, rename, fsync dir.
absl::Status AtomicWrite(const std::string& dir, const std::string& path,
                         absl::string_view contents) {
  absl::StatusOr<std::string> tmp = WriteTemp(path, contents, /*sync=*/true);
  if (!tmp.ok()) return tmp.status();
  if (::rename(tmp->c_str(), path.c_str()) != 0) {
    const absl::Status status = ErrnoError("cannot rename", *tmp);
    ::unlink(tmp->c_str());
    return status;
  }
  return FsyncDir(dir);
}

bool IsMapFileName(const std::string& name, std::string* map_id) {
  const size_t suffix = sizeof(kSuffix) - 1;
  if (name.size() <= suffix || name.compare(name.size() - suffix, suffix, kSuffix) != 0)
    return false;
  *map_id = name.substr(0, name.size() - suffix);
  return ValidateMapId(*map_id).ok();
}

}  // namespace

absl::StatusOr<std::unique_ptr<MapStore>> MapStore::OpenLocked(const std::string& dir, bool index) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    return absl::InternalError(
        absl::StrCat("cannot create store directory ", dir, ": ", ec.message()));
  // One server per store: a second one would index a different state and
  // the two would disagree about what exists.
  const std::string lock_path = dir + "/" + kLockName;
  const int lock_fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (lock_fd < 0) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot open the store lock file ", lock_path, ": ", std::strerror(errno)));
  }
  if (::flock(lock_fd, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    ::close(lock_fd);
    if (err == EWOULDBLOCK) {
      return absl::FailedPreconditionError(
          absl::StrCat("store directory ", dir, " is in use by another covplan-server (", lock_path,
                       " is locked); stop it or choose another --store_dir"));
    }
    return absl::FailedPreconditionError(
        absl::StrCat("cannot lock ", lock_path, ": ", std::strerror(err)));
  }
  std::unique_ptr<MapStore> store(new MapStore(dir));
  store->lock_fd_ = lock_fd;
  if (!index) {
    absl::MutexLock lock(&store->mu_);
    store->loading_ = true;
    return store;
  }
  if (absl::Status s = store->LoadIndex(nullptr); !s.ok()) return s;
  return store;
}

absl::StatusOr<std::unique_ptr<MapStore>> MapStore::Open(const std::string& dir) {
  return OpenLocked(dir, /*index=*/true);
}

absl::Status MapStore::LoadIndex(const std::atomic<bool>* stop) {
  {
    absl::MutexLock lock(&mu_);
    loading_ = true;
  }
  std::error_code ec;
  std::map<std::string, v1::MapInfo> index;
  std::set<std::string> corrupted;
  for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) {
    if (stop != nullptr && stop->load()) return absl::CancelledError("index load stopped");
    const std::string name = entry.path().filename().string();
    // Only regular files (not symlinks, FIFOs, devices: a FIFO would block
    // the open forever).
    std::error_code type_ec;
    if (entry.symlink_status(type_ec).type() != std::filesystem::file_type::regular) continue;
    if (name.find(".tmp.") != std::string::npos) {  // left over by a crash mid-write
      std::filesystem::remove(entry.path(), type_ec);
      continue;
    }
    std::string map_id;
    if (!IsMapFileName(name, &map_id)) continue;
    absl::StatusOr<v1::GetMapResponse> stored = ReadVerified(entry.path().string());
    if (stored.ok() && stored->info().map_id() == map_id) {
      index[map_id] = stored->info();
    } else {
      corrupted.insert(map_id);
    }
  }
  if (ec) return absl::InternalError(absl::StrCat("cannot list ", dir_, ": ", ec.message()));
  absl::MutexLock lock(&mu_);
  index_ = std::move(index);
  corrupted_ = std::move(corrupted);
  loading_ = false;
  return absl::OkStatus();
}

bool MapStore::loading() const {
  absl::MutexLock lock(&mu_);
  return loading_;
}

MapStore::~MapStore() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the flock
}

absl::Status MapStore::Check(const std::string& map_id) const {
  absl::MutexLock lock(&mu_);
  if (loading_) return LoadingError();
  if (corrupted_.count(map_id) != 0) {
    return absl::DataLossError(
        absl::StrCat("map ", map_id, " is corrupted on disk; PutMap it again"));
  }
  if (index_.count(map_id) == 0) {
    return absl::NotFoundError(absl::StrCat("unknown map_id ", map_id, "; PutMap it first"));
  }
  return absl::OkStatus();
}

absl::Status MapStore::ProbeWritable() {
  absl::MutexLock write_lock(&write_mu_);
  absl::Status status = AtomicWrite(dir_, dir_ + "/" + kProbeName, "probe\n");
  writable_.store(status.ok());
  return status;
}

std::string MapStore::PathFor(const std::string& map_id) const {
  return absl::StrCat(dir_, "/", map_id, kSuffix);
}

absl::StatusOr<v1::GetMapResponse> MapStore::ReadVerified(const std::string& path) const {
  // O_NONBLOCK: a FIFO or device planted under a map's name must not hang
  // the server; only a regular file is read.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOFOLLOW);
  if (fd < 0) {
    if (errno == ENOENT) return absl::NotFoundError("map file is missing");
    return absl::DataLossError(absl::StrCat("map file cannot be opened: ", std::strerror(errno)));
  }
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return absl::DataLossError("map file is not a regular file");
  }
  std::string contents(static_cast<size_t>(st.st_size), '\0');
  size_t got = 0;
  while (got < contents.size()) {
    const ssize_t n = ::read(fd, contents.data() + got, contents.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    got += static_cast<size_t>(n);
  }
  ::close(fd);
  contents.resize(got);
  // Three header lines, then the payload.
  size_t pos = 0;
  absl::string_view lines[3];
  for (absl::string_view& line : lines) {
    const size_t end = contents.find('\n', pos);
    if (end == std::string::npos) return absl::DataLossError("truncated header");
    line = absl::string_view(contents).substr(pos, end - pos);
    pos = end + 1;
  }
  uint64_t size = 0;
  if (lines[0] != kMagic || lines[1].size() != 64 || !absl::SimpleAtoi(lines[2], &size)) {
    return absl::DataLossError("bad header");
  }
  const absl::string_view payload = absl::string_view(contents).substr(pos);
  if (payload.size() != size) {
    return absl::DataLossError(
        absl::StrCat("payload is ", payload.size(), " bytes, header says ", size, " (truncated?)"));
  }
  if (Sha256Hex(payload) != lines[1]) {
    return absl::DataLossError("checksum mismatch");
  }
  v1::GetMapResponse stored;
  if (!stored.ParseFromArray(payload.data(), static_cast<int>(payload.size()))) {
    return absl::DataLossError("payload does not parse");
  }
  return stored;
}

void MapStore::MarkCorrupted(const std::string& map_id) const {
  absl::MutexLock lock(&mu_);
  corrupted_.insert(map_id);
  index_.erase(map_id);
}

absl::StatusOr<bool> MapStore::Put(const v1::MapInfo& info, const v1::Map& map) {
  const std::string& map_id = info.map_id();
  if (absl::Status s = ValidateMapId(map_id); !s.ok()) return s;
  absl::MutexLock write_lock(&write_mu_);
  bool indexed = false;
  {
    absl::MutexLock lock(&mu_);
    if (loading_) return LoadingError();
    indexed = index_.count(map_id) != 0;
  }
  if (indexed) {
    // Idempotent only if the copy on disk is still intact: a file damaged
    // since it was indexed is rewritten by this one Put.
    absl::StatusOr<v1::GetMapResponse> on_disk = ReadVerified(PathFor(map_id));
    if (on_disk.ok() && on_disk->info().map_id() == map_id) return false;
    LogLine("warn", "stored map damaged, rewritten by PutMap",
            {{"map_id", map_id},
             {"detail", on_disk.ok() ? "id mismatch" : std::string(on_disk.status().message())}});
  }
  v1::GetMapResponse stored;
  *stored.mutable_info() = info;
  stored.mutable_info()->set_created_unix_ms(absl::ToUnixMillis(absl::Now()));
  *stored.mutable_map() = map;
  stored.mutable_info()->set_size_bytes(static_cast<int32_t>(map.ByteSizeLong()));
  std::string payload;
  if (!stored.SerializeToString(&payload)) return absl::InternalError("cannot serialise map");
  const std::string contents =
      absl::StrCat(kMagic, "\n", Sha256Hex(payload), "\n", payload.size(), "\n", payload);
  if (absl::Status s = AtomicWrite(dir_, PathFor(map_id), contents); !s.ok()) {
    if (!absl::IsInternal(s)) writable_.store(false);
    return s;
  }
  writable_.store(true);
  absl::MutexLock lock(&mu_);
  index_[map_id] = stored.info();
  corrupted_.erase(map_id);
  return true;
}

absl::StatusOr<v1::GetMapResponse> MapStore::Get(const std::string& map_id) const {
  if (absl::Status s = ValidateMapId(map_id); !s.ok()) return s;
  if (absl::Status s = Check(map_id); !s.ok()) return s;
  absl::StatusOr<v1::GetMapResponse> stored = ReadVerified(PathFor(map_id));
  if (!stored.ok() || stored->info().map_id() != map_id) {
    MarkCorrupted(map_id);
    return absl::DataLossError(absl::StrCat("map ", map_id, " is corrupted on disk (",
                                            stored.ok() ? "id mismatch" : stored.status().message(),
                                            "); PutMap it again"));
  }
  return stored;
}

std::vector<v1::MapInfo> MapStore::List(std::vector<std::string>* corrupted) const {
  absl::MutexLock lock(&mu_);
  std::vector<v1::MapInfo> maps;
  maps.reserve(index_.size());
  for (const auto& [id, info] : index_) maps.push_back(info);
  if (corrupted != nullptr) corrupted->assign(corrupted_.begin(), corrupted_.end());
  return maps;
}

absl::StatusOr<std::vector<v1::MapInfo>> MapStore::ListPage(
    const std::string& after, int limit, bool* more, std::vector<std::string>* corrupted) const {
  absl::MutexLock lock(&mu_);
  if (loading_) return LoadingError();
  std::vector<v1::MapInfo> maps;
  auto it = after.empty() ? index_.begin() : index_.upper_bound(after);
  for (; it != index_.end() && static_cast<int>(maps.size()) < limit; ++it)
    maps.push_back(it->second);
  *more = it != index_.end();
  if (corrupted != nullptr) corrupted->assign(corrupted_.begin(), corrupted_.end());
  return maps;
}

absl::StatusOr<bool> MapStore::Delete(const std::string& map_id) {
  if (absl::Status s = ValidateMapId(map_id); !s.ok()) return s;
  absl::MutexLock write_lock(&write_mu_);
  {
    absl::MutexLock lock(&mu_);
    if (loading_) return LoadingError();
    if (index_.count(map_id) == 0 && corrupted_.count(map_id) == 0) return false;
  }
  // The index changes only once the file is gone: a failed unlink (e.g. a
  // read-only store) leaves the map listed and served, as it will be after a
  // restart.
  const std::string path = PathFor(map_id);
  if (::unlink(path.c_str()) != 0 && errno != ENOENT) {
    absl::Status s = ErrnoError("delete", path);
    if (!absl::IsInternal(s)) writable_.store(false);
    return s;
  }
  {
    absl::MutexLock lock(&mu_);
    index_.erase(map_id);
    corrupted_.erase(map_id);
  }
  if (absl::Status s = FsyncDir(dir_); !s.ok()) return s;
  return true;
}

int64_t MapStore::size() const {
  absl::MutexLock lock(&mu_);
  return static_cast<int64_t>(index_.size());
}

absl::Status MapStore::PutState(const std::string& name, absl::string_view contents) {
  if (!IsStateName(name))
    return absl::InvalidArgumentError(absl::StrCat("bad state file name ", name));
  absl::MutexLock write_lock(&write_mu_);
  return AtomicWrite(dir_, dir_ + "/" + name, contents);
}

absl::StatusOr<std::string> MapStore::GetState(const std::string& name) const {
  if (!IsStateName(name))
    return absl::InvalidArgumentError(absl::StrCat("bad state file name ", name));
  std::ifstream in(dir_ + "/" + name, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat("no state file ", name));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

absl::Status MapStore::PutPlan(const std::string& plan_id, absl::string_view contents) {
  if (!IsPlanId(plan_id)) return absl::InvalidArgumentError(absl::StrCat("bad plan id ", plan_id));
  const std::string dir = dir_ + "/plans";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return absl::InternalError(absl::StrCat("cannot create ", dir, ": ", ec.message()));
  return AtomicWrite(dir, dir + "/" + plan_id + ".plan", contents);
}

absl::Status MapStore::PutPlans(const std::vector<std::pair<std::string, std::string>>& plans) {
  const std::string dir = dir_ + "/plans";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return absl::InternalError(absl::StrCat("cannot create ", dir, ": ", ec.message()));
  absl::Status first;
  std::vector<std::pair<std::string, std::string>> written;  // temp file, final path
  for (const auto& [plan_id, contents] : plans) {
    if (!IsPlanId(plan_id)) {
      first.Update(absl::InvalidArgumentError(absl::StrCat("bad plan id ", plan_id.substr(0, 80))));
      continue;
    }
    const std::string path = dir + "/" + plan_id + ".plan";
    absl::StatusOr<std::string> tmp = WriteTemp(path, contents, /*sync=*/false);
    if (tmp.ok()) {
      written.emplace_back(*std::move(tmp), path);
    } else {
      first.Update(tmp.status());
    }
  }
  if (written.empty()) return first;
  // The contents reach the disk before any rename makes them visible.
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  const bool synced = dir_fd >= 0 && ::syncfs(dir_fd) == 0;
  if (!synced) first.Update(ErrnoError("cannot sync", dir));
  if (dir_fd >= 0) ::close(dir_fd);
  for (const auto& [tmp, path] : written) {
    if (!synced || ::rename(tmp.c_str(), path.c_str()) != 0) {
      if (synced) first.Update(ErrnoError("cannot rename", tmp));
      ::unlink(tmp.c_str());
    }
  }
  if (synced) first.Update(FsyncDir(dir));
  return first;
}

absl::StatusOr<std::string> MapStore::GetPlan(const std::string& plan_id) const {
  if (!IsPlanId(plan_id))
    return absl::NotFoundError(absl::StrCat("no plan ", plan_id.substr(0, 80)));
  std::ifstream in(dir_ + "/plans/" + plan_id + ".plan", std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat("no stored plan ", plan_id));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

absl::Status MapStore::PutProgress(const std::string& plan_id, absl::string_view contents) {
  if (!IsPlanId(plan_id))
    return absl::InvalidArgumentError(absl::StrCat("bad plan id ", plan_id.substr(0, 80)));
  const std::string dir = dir_ + "/plans";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    return absl::InternalError(absl::StrCat("cannot create the plans directory: ", ec.message()));
  return AtomicWrite(dir, dir + "/" + plan_id + ".progress", contents);
}

absl::StatusOr<std::string> MapStore::GetProgress(const std::string& plan_id) const {
  if (!IsPlanId(plan_id)) return absl::NotFoundError("no progress for that plan id");
  std::ifstream in(dir_ + "/plans/" + plan_id + ".progress", std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat("no recorded progress for plan ", plan_id));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

absl::Status MapStore::TouchPlan(const std::string& plan_id) {
  if (!IsPlanId(plan_id))
    return absl::NotFoundError(absl::StrCat("no plan ", plan_id.substr(0, 80)));
  std::error_code ec;
  std::filesystem::last_write_time(dir_ + "/plans/" + plan_id + ".plan",
                                   std::filesystem::file_time_type::clock::now(), ec);
  if (ec) return absl::NotFoundError(absl::StrCat("no stored plan ", plan_id, ": ", ec.message()));
  return absl::OkStatus();
}

int64_t MapStore::TrimPlans(int64_t keep) {
  std::error_code ec;
  std::vector<std::pair<std::filesystem::file_time_type, std::filesystem::path>> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir_ + "/plans", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.find(".tmp.") != std::string::npos) {
      // A write that a crash interrupted; a younger one may be another
      // thread's write in progress.
      const auto written = entry.last_write_time(ec);
      if (!ec &&
          std::filesystem::file_time_type::clock::now() - written > std::chrono::minutes(1)) {
        std::filesystem::remove(entry.path(), ec);
      }
      continue;
    }
    files.emplace_back(entry.last_write_time(ec), entry.path());
  }
  if (static_cast<int64_t>(files.size()) <= keep) return 0;
  std::sort(files.begin(), files.end());
  int64_t removed = 0;
  for (size_t i = 0; i + keep < files.size(); ++i)
    removed += std::filesystem::remove(files[i].second, ec);
  return removed;
}

}  // namespace covplan
