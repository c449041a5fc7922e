// Per-tenant quotas: the quota file's lines over the defaults, its errors
// naming the line, reloads that keep the previous table on a bad file; the
// admission of solves per tenant (a tenant over max_solves + max_queued is
// refused naming the quota while another tenant is admitted, and its slots
// come back; queue pricing follows the turns); the pool never runs more of a tenant's solves than
// max_solves.
#include "server/tenant_quotas.h"

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "absl/synchronization/notification.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/admission.h"
#include "server/metrics.h"
#include "server/tenant_tokens.h"
#include "server/worker_pool.h"

namespace covplan {
namespace {

using ::testing::HasSubstr;

TEST(TenantQuotasTest, LinesOverrideTheDefaultsFieldByField) {
  TenantQuota defaults;
  defaults.max_solves = 2;
  defaults.max_queued = 8;
  defaults.max_maps = 100;
  const auto table = TenantQuotas::Parse(
      "# tenant quotas\n"
      "fleet-a  max_solves=1 max_queued=2\n"
      "\n"
      "fleet.b\tmax_maps=0   \n",
      defaults);
  ASSERT_TRUE(table.ok()) << table.status();
  ASSERT_EQ(table->size(), 2u);
  EXPECT_EQ(table->at("fleet-a").max_solves, 1);
  EXPECT_EQ(table->at("fleet-a").max_queued, 2);
  EXPECT_EQ(table->at("fleet-a").max_maps, 100);
  EXPECT_EQ(table->at("fleet.b").max_solves, 2);
  EXPECT_EQ(table->at("fleet.b").max_maps, 0);
}

TEST(TenantQuotasTest, MalformedLinesAreNamed) {
  const TenantQuota defaults;
  const struct {
    const char* text;
    const char* message;
  } cases[] = {
      {"a max_solves=1\nb max_solves=-1\n", "line 2: \"max_solves=-1\": expected name=N"},
      {"a max_threads=3\n", "line 1: unknown quota \"max_threads\""},
      {"a max_solves=1\na max_maps=3\n", "line 2: tenant a twice"},
      {"a\n", "line 1: tenant a sets no quota"},
      {"a max_solves=99999999999\n", "line 1: max_solves is too large"},
      {"bad/name max_solves=1\n", "line 1: expected \"<tenant> name=N ...\""},
      {"a max_solves\n", "line 1: \"max_solves\": expected name=N"},
  };
  for (const auto& c : cases) {
    const auto table = TenantQuotas::Parse(c.text, defaults);
    ASSERT_FALSE(table.ok()) << c.text;
    EXPECT_EQ(table.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(table.status().message(), HasSubstr(c.message)) << c.text;
  }
}

TEST(TenantQuotasTest, LookupIsByTagAndABadReloadKeepsTheTable) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("covplan_quotas_" + std::to_string(getpid())))
          .string();
  std::ofstream(path) << "alpha max_solves=1\n";
  TenantQuota defaults;
  defaults.max_solves = 4;
  auto quotas = TenantQuotas::Load(defaults, path);
  ASSERT_TRUE(quotas.ok()) << quotas.status();
  EXPECT_EQ((*quotas)->For(TenantTag("alpha")).max_solves, 1);
  EXPECT_EQ((*quotas)->For(TenantTag("beta")).max_solves, 4);
  EXPECT_EQ((*quotas)->For("").max_solves, 4);  // no token file: the defaults
  std::ofstream(path) << "alpha max_solves=1\nbeta max_solves=x\n";
  const auto bad = (*quotas)->Reload();
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(bad.status().message(), HasSubstr("--tenant_quota_file"));
  EXPECT_THAT(bad.status().message(), HasSubstr("line 2"));
  EXPECT_EQ((*quotas)->For(TenantTag("alpha")).max_solves, 1);
  std::ofstream(path) << "beta max_solves=2\n";
  ASSERT_TRUE((*quotas)->Reload().ok());
  EXPECT_EQ((*quotas)->For(TenantTag("alpha")).max_solves, 4);
  EXPECT_EQ((*quotas)->For(TenantTag("beta")).max_solves, 2);
  std::filesystem::remove(path);
  EXPECT_FALSE(TenantQuotas::Load(defaults, path).ok());
}

CallInfo CallOf(const std::string& tenant) {
  CallInfo call;
  call.method = "Plan";
  call.start = absl::Now();
  call.tenant = tenant;
  call.tenant_tag = TenantTag(tenant);
  return call;
}

// A solve admission of 2 workers and a queue of 8 whose tenants all have
// `max_solves` and `max_queued` (0: none).
class AdmissionBed {
 public:
  AdmissionBed(int max_solves, int max_queued)
      : options_(Options()),
        quotas_(*TenantQuotas::Load(TenantQuota{max_solves, max_queued, 0}, "")),
        pool_(options_.worker_threads, 2 * (options_.worker_threads + options_.max_queue)),
        admission_(options_, &metrics_, &pool_, quotas_.get()) {}
  SolveAdmission& admission() { return admission_; }
  WorkerPool& pool() { return pool_; }

 private:
  static ServiceOptions Options() {
    ServiceOptions options;
    options.worker_threads = 2;
    options.max_queue = 8;
    return options;
  }
  const ServiceOptions options_;
  std::unique_ptr<TenantQuotas> quotas_;
  ServerMetrics metrics_;
  WorkerPool pool_;
  SolveAdmission admission_;
};

TEST(SolveAdmissionTest, ATenantOverItsQuotaIsRefusedAndOthersAreAdmitted) {
  AdmissionBed bed(/*max_solves=*/1, /*max_queued=*/2);
  SolveAdmission& admission = bed.admission();
  const CallInfo alpha = CallOf("alpha");
  const CallInfo beta = CallOf("beta");
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(admission.Admit(alpha).ok()) << i;
  const absl::Status refused = admission.Admit(alpha);
  EXPECT_EQ(refused.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(refused.message(),
              HasSubstr("tenant alpha is over its quota of 1 running and 2 queued solves"));
  EXPECT_THAT(refused.message(), HasSubstr("--tenant_quota_file"));
  EXPECT_TRUE(admission.Admit(beta).ok());
  // A slot given back is alpha's again.
  admission.Release(alpha.tenant_tag);
  EXPECT_TRUE(admission.Admit(alpha).ok());
  EXPECT_FALSE(admission.Admit(alpha).ok());
  // Every slot given back is admitted again.
  for (int i = 0; i < 3; ++i) admission.Release(alpha.tenant_tag);
  admission.Release(beta.tenant_tag);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(admission.Admit(alpha).ok()) << i;
}

// Queue pricing sees the turns: a tenant's capped solves are not in front of
// another tenant's call, so a Plan with a short deadline is admitted while
// the busy tenant's queue is long (priced over all admitted calls it was
// refused: 3 ahead of 2 workers at 10 s a solve).
TEST(SolveAdmissionTest, AnotherTenantsQueueDoesNotPriceACallOut) {
  AdmissionBed bed(/*max_solves=*/1, /*max_queued=*/2);
  SolveAdmission& admission = bed.admission();
  admission.RecordPlanTime(absl::Seconds(10), /*hit=*/false);
  const CallInfo alpha = CallOf("alpha");
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(admission.AdmitPlan(alpha, false).ok()) << i;
  CallInfo beta = CallOf("beta");
  beta.deadline = absl::Now() + absl::Seconds(1);
  EXPECT_TRUE(admission.AdmitPlan(beta, false).ok());
  // Beta's second call is behind its first and one of alpha's: priced out.
  const absl::Status second = admission.AdmitPlan(beta, false);
  EXPECT_EQ(second.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(second.message(), HasSubstr("expected queue wait"));
}

TEST(SolveAdmissionTest, ThePoolRunsOneSolveOfATenantAtATime) {
  AdmissionBed bed(/*max_solves=*/1, /*max_queued=*/0);
  SolveAdmission& admission = bed.admission();
  WorkerPool& pool = bed.pool();
  absl::Notification release;
  std::atomic<int> alpha_running{0};
  std::atomic<int> alpha_most{0};
  std::atomic<int> done{0};
  const CallInfo alpha = CallOf("alpha");
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(admission.Admit(alpha).ok());
    SolveAdmission::Task task;
    task.tenant_tag = alpha.tenant_tag;
    task.solve = [&] {
      alpha_most.store(std::max(alpha_most.load(), alpha_running.fetch_add(1) + 1));
      release.WaitForNotificationWithTimeout(absl::Seconds(5));
      alpha_running.fetch_sub(1);
    };
    task.reply = [&] { done.fetch_add(1); };
    ASSERT_TRUE(admission.Submit(std::move(task)));
  }
  // Beta's solve runs on the second worker while alpha's wait.
  const CallInfo beta = CallOf("beta");
  ASSERT_TRUE(admission.Admit(beta).ok());
  absl::Notification beta_done;
  SolveAdmission::Task task;
  task.tenant_tag = beta.tenant_tag;
  task.solve = [] {};
  task.reply = [&] { beta_done.Notify(); };
  ASSERT_TRUE(admission.Submit(std::move(task)));
  EXPECT_TRUE(beta_done.WaitForNotificationWithTimeout(absl::Seconds(5)));
  EXPECT_EQ(pool.queued(), 2);
  release.Notify();
  pool.Shutdown();
  EXPECT_EQ(done.load(), 3);
  EXPECT_EQ(alpha_most.load(), 1);
}

}  // namespace
}  // namespace covplan
