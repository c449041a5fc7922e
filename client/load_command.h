// `covplan load`: drives Plan calls at a fixed concurrency against a server
// and prints one JSON object: requests, ok, per-code counts, latency
// percentiles and `late` (replies that arrived after their deadline).
//
//   covplan load --server 127.0.0.1:50051 --map maps/sample_office.yaml
//       --concurrency 4 --duration 10 --deadline-ms 500
//   covplan load --server 127.0.0.1:8080 --maps /tmp/load-maps --zipf 1 --inline
//   covplan load --server 127.0.0.1:50051 --map maps/sample_office.yaml --random-start
//
// --random-start draws each request's start pose uniformly from the free
// cells the robot can reach (the map's drive grid at the tool width, built
// locally), heading uniform in [0, 2 pi), from --seed: the same sequence per
// worker on every run. The report counts replies by PlanStats.plan_source and
// gives their mean estimated duration.
//
// Thread-safety: not applicable (command entry point).
#ifndef COVPLAN_CLIENT_LOAD_COMMAND_H_
#define COVPLAN_CLIENT_LOAD_COMMAND_H_

#include <map>
#include <string>
#include <vector>

namespace covplan {

int RunLoadCommand(const std::vector<std::string>& args);

// Summary of a load run (exposed for tests).
struct LoadReport {
  int64_t requests = 0;
  int64_t ok = 0;
  int64_t late = 0;
  int64_t cut_short = 0;
  std::map<std::string, int64_t> codes;  // status code name -> count
  std::vector<double> latencies_ms;      // every reply
  double duration_s = 0;
  int concurrency = 0;
  int maps = 1;                      // distinct maps the requests were spread over
  std::vector<std::string> map_ids;  // acknowledged by PutMap (empty with --inline)
  int64_t deadline_ms = 0;
  bool random_start = false;
  std::map<std::string, int64_t> plan_sources;  // "cold", "cache_hit", ... -> OK replies
  double estimated_duration_sum_s = 0;          // over OK replies

  std::string ToJson() const;  // percentiles are computed here
};

}  // namespace covplan

#endif  // COVPLAN_CLIENT_LOAD_COMMAND_H_
