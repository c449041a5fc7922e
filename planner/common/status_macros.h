// Minimal status-propagation macros. Debian's abseil (20220623) ships none.
//
//   RETURN_IF_ERROR(DoThing());
//   ASSIGN_OR_RETURN(Grid grid, BuildGrid(map, options));
#ifndef COVPLAN_PLANNER_COMMON_STATUS_MACROS_H_
#define COVPLAN_PLANNER_COMMON_STATUS_MACROS_H_

#include "absl/status/status.h"
#include "absl/status/statusor.h"

#define COVPLAN_CONCAT_INNER_(a, b) a##b
#define COVPLAN_CONCAT_(a, b) COVPLAN_CONCAT_INNER_(a, b)

#define RETURN_IF_ERROR(expr)                          \
  do {                                                 \
    const ::absl::Status covplan_status_ = (expr);     \
    if (!covplan_status_.ok()) return covplan_status_; \
  } while (0)

#define COVPLAN_ASSIGN_OR_RETURN_IMPL_(tmp, lhs, expr) \
  auto tmp = (expr);                                   \
  if (!tmp.ok()) return tmp.status();                  \
  lhs = std::move(tmp).value()

#define ASSIGN_OR_RETURN(lhs, expr) \
  COVPLAN_ASSIGN_OR_RETURN_IMPL_(COVPLAN_CONCAT_(statusor_, __LINE__), lhs, expr)

#endif  // COVPLAN_PLANNER_COMMON_STATUS_MACROS_H_
