// The JSON API (--http_port) against the gRPC API of the same in-process
// server: the same answers method by method (the JSON parsed back into the
// proto and compared field by field), the same tokens and tenants, errors
// with the gRPC code and message under the mapped HTTP status, and bad HTTP
// input (malformed JSON, wrong types, unknown fields, paths and methods,
// oversized bodies, slow clients) answered clearly while gRPC goes on.
#include <arpa/inet.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
#include <google/protobuf/util/message_differencer.h>
#include <grpcpp/grpcpp.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "api/digest.h"
#include "covplan/v1/covplan.grpc.pb.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "server/covplan_server.h"
#include "tests/server/grpc_probe.h"
#include "tests/testing/test_maps.h"

namespace covplan {
namespace {

namespace pb = google::protobuf;
using ::covplan::testing::AsciiToPgm;
using ::covplan::testing::HttpReply;
using ::covplan::testing::HttpRequest;
using ::covplan::testing::PlanRequestFor;
using ::covplan::testing::RasterMap;
using ::covplan::testing::TwoRooms;

constexpr char kAlpha[] = "alpha-secret-token";
constexpr char kBeta[] = "beta-secret-token";

std::string Json(const pb::Message& m) {
  std::string out;
  EXPECT_TRUE(pb::util::MessageToJsonString(m, &out).ok());
  return out;
}

template <typename M>
M FromJson(const std::string& json) {
  M m;
  const auto parsed = pb::util::JsonStringToMessage(json, &m);
  EXPECT_TRUE(parsed.ok()) << parsed << " in " << json.substr(0, 200);
  return m;
}

// The error body's fields.
struct ErrorBody {
  int code = -1;
  std::string status, message;
};
ErrorBody ErrorOf(const HttpReply& reply) {
  const pb::Struct s = FromJson<pb::Struct>(reply.body);
  ErrorBody e;
  const auto& f = s.fields();
  if (f.contains("code")) e.code = static_cast<int>(f.at("code").number_value());
  if (f.contains("status")) e.status = f.at("status").string_value();
  if (f.contains("message")) e.message = f.at("message").string_value();
  return e;
}

class HttpGatewayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (std::filesystem::temp_directory_path() / "covplan_http_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    stub_.reset();
    server_.reset();
    std::filesystem::remove_all(dir_);
  }
  void Start(bool tokens = false, int max_message_bytes = 80 << 20,
             int request_timeout_ms = 15000) {
    ServerConfig config;
    config.port = 0;
    config.metrics_port = -1;
    config.http_port = 0;
    config.http_request_timeout_ms = request_timeout_ms;
    config.max_message_bytes = max_message_bytes;
    config.store_dir = dir_ + "/maps";
    if (tokens) {
      config.token_file = dir_ + "/tokens.txt";
      std::ofstream(config.token_file) << Sha256Hex(kAlpha) << " alpha\n"
                                       << Sha256Hex(kBeta) << " beta\n";
    }
    absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = std::move(*server);
    ASSERT_GT(server_->http_port(), 0);
    stub_ = v1::CoveragePlanner::NewStub(grpc::CreateChannel(
        absl::StrCat("127.0.0.1:", server_->port()), grpc::InsecureChannelCredentials()));
  }
  std::unique_ptr<grpc::ClientContext> Ctx(const std::string& token = "") {
    auto c = std::make_unique<grpc::ClientContext>();
    c->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
    if (!token.empty()) c->AddMetadata("authorization", absl::StrCat("Bearer ", token));
    return c;
  }
  HttpReply Post(const std::string& method, const std::string& body, const std::string& token = "",
                 std::vector<std::string> headers = {}) {
    if (!token.empty()) headers.push_back(absl::StrCat("Authorization: Bearer ", token));
    headers.push_back("Content-Type: application/json");
    absl::StatusOr<HttpReply> r =
        HttpRequest(server_->http_port(), "POST", "/v1/" + method, headers, body);
    EXPECT_TRUE(r.ok()) << r.status();
    return r.ok() ? *r : HttpReply{};
  }
  static v1::PutMapRequest TwoRoomsMap() {
    v1::PutMapRequest put;
    *put.mutable_map() = RasterMap(AsciiToPgm(TwoRooms(), 4), 0.05);
    put.set_name("two rooms");
    return put;
  }

  std::string dir_;
  std::unique_ptr<CovplanServer> server_;
  std::unique_ptr<v1::CoveragePlanner::Stub> stub_;
};

TEST_F(HttpGatewayTest, EveryUnaryMethodAnswersAsGrpcDoes) {
  Start();
  // PutMap over JSON (the image travels base64, as the mapping says).
  const HttpReply put = Post("PutMap", Json(TwoRoomsMap()));
  ASSERT_EQ(put.status, 200) << put.body;
  EXPECT_NE(put.headers.find("application/json"), std::string::npos);
  const auto stored = FromJson<v1::PutMapResponse>(put.body);
  v1::PutMapResponse grpc_stored;
  ASSERT_TRUE(stub_->PutMap(Ctx().get(), TwoRoomsMap(), &grpc_stored).ok());
  EXPECT_EQ(stored.info().map_id(), grpc_stored.info().map_id()) << "same map, same id";
  const std::string map_id = stored.info().map_id();

  // Read-only methods: the JSON answer is the gRPC answer.
  v1::ListMapsResponse grpc_list;
  ASSERT_TRUE(stub_->ListMaps(Ctx().get(), v1::ListMapsRequest(), &grpc_list).ok());
  const HttpReply list = Post("ListMaps", "{}");
  ASSERT_EQ(list.status, 200) << list.body;
  EXPECT_TRUE(
      pb::util::MessageDifferencer::Equals(FromJson<v1::ListMapsResponse>(list.body), grpc_list));
  v1::GetMapRequest get;
  get.set_map_id(map_id);
  v1::GetMapResponse grpc_map;
  ASSERT_TRUE(stub_->GetMap(Ctx().get(), get, &grpc_map).ok());
  const HttpReply map = Post("GetMap", Json(get));
  ASSERT_EQ(map.status, 200) << map.body.substr(0, 200);
  EXPECT_TRUE(
      pb::util::MessageDifferencer::Equals(FromJson<v1::GetMapResponse>(map.body), grpc_map));

  // A plan made over gRPC, fetched over both.
  v1::PlanResponse grpc_plan;
  ASSERT_TRUE(stub_->Plan(Ctx().get(), PlanRequestFor(map_id, 0.3), &grpc_plan).ok());
  v1::GetPlanRequest get_plan;
  get_plan.set_plan_id(grpc_plan.plan_id());
  v1::PlanResponse grpc_fetched;
  ASSERT_TRUE(stub_->GetPlan(Ctx().get(), get_plan, &grpc_fetched).ok());
  const HttpReply fetched = Post("GetPlan", Json(get_plan));
  ASSERT_EQ(fetched.status, 200) << fetched.body.substr(0, 200);
  EXPECT_TRUE(
      pb::util::MessageDifferencer::Equals(FromJson<v1::PlanResponse>(fetched.body), grpc_fetched));

  // A plan made over JSON: the same exact optimum of ranks and the same
  // cells as gRPC's (the tour order is anytime), addressable by gRPC.
  const HttpReply planned = Post("Plan", Json(PlanRequestFor(map_id, 0.3)));
  ASSERT_EQ(planned.status, 200) << planned.body.substr(0, 300);
  const auto json_plan = FromJson<v1::PlanResponse>(planned.body);
  EXPECT_EQ(json_plan.stats().num_ranks(), grpc_plan.stats().num_ranks());
  EXPECT_GT(json_plan.stats().num_ranks(), 0);
  EXPECT_EQ(json_plan.stats().covered_cells(), grpc_plan.stats().covered_cells());
  get_plan.set_plan_id(json_plan.plan_id());
  v1::PlanResponse again;
  EXPECT_TRUE(stub_->GetPlan(Ctx().get(), get_plan, &again).ok());

  // DeleteMap over JSON; gRPC no longer finds it.
  v1::DeleteMapRequest del;
  del.set_map_id(map_id);
  EXPECT_EQ(Post("DeleteMap", Json(del)).status, 200);
  v1::GetMapResponse gone;
  EXPECT_EQ(stub_->GetMap(Ctx().get(), get, &gone).error_code(), grpc::StatusCode::NOT_FOUND);
}

TEST_F(HttpGatewayTest, ErrorsCarryTheGrpcCodeAndMessage) {
  Start();
  // A planning error: the same code and message as over gRPC.
  v1::PlanRequest bad = PlanRequestFor(std::string(64, 'a'), 0.3);
  v1::PlanResponse ignored;
  const grpc::Status grpc_error = stub_->Plan(Ctx().get(), bad, &ignored);
  const HttpReply missing = Post("Plan", Json(bad));
  EXPECT_EQ(missing.status, 404);
  EXPECT_EQ(ErrorOf(missing).code, grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(ErrorOf(missing).status, "NOT_FOUND");
  EXPECT_EQ(ErrorOf(missing).message, grpc_error.error_message());

  struct Case {
    std::string body, expect_in_message;
  };
  for (const Case& c :
       std::vector<Case>{{"{\"mapId\": ", "PlanRequest"},    // malformed JSON
                         {"{\"mapId\": 5}", "PlanRequest"},  // wrong type
                         {"[1, 2]", "PlanRequest"},          // not an object
                         {"{\"mapIdd\": \"x\"}", "mapIdd"},  // unknown field
                         {"{\"robot\": {\"toolWidthM\": \"wide\"}}", "PlanRequest"}}) {
    const HttpReply r = Post("Plan", c.body);
    EXPECT_EQ(r.status, 400) << c.body;
    const ErrorBody e = ErrorOf(r);
    EXPECT_EQ(e.code, grpc::StatusCode::INVALID_ARGUMENT) << c.body;
    EXPECT_NE(e.message.find(c.expect_in_message), std::string::npos) << e.message;
  }
  // A request the planner refuses.
  v1::PlanRequest negative = PlanRequestFor("m", -1.0);
  const HttpReply refused = Post("Plan", Json(negative));
  EXPECT_EQ(refused.status, 400);
  EXPECT_EQ(ErrorOf(refused).code, grpc::StatusCode::INVALID_ARGUMENT);

  EXPECT_EQ(Post("NoSuchMethod", "{}").status, 404);
  EXPECT_NE(ErrorOf(Post("NoSuchMethod", "{}")).message.find("NoSuchMethod"), std::string::npos);
  const HttpReply drive = Post("Drive", "{}");
  EXPECT_EQ(drive.status, 501);
  EXPECT_EQ(ErrorOf(drive).code, grpc::StatusCode::UNIMPLEMENTED);
  absl::StatusOr<HttpReply> get = HttpRequest(server_->http_port(), "GET", "/v1/ListMaps");
  ASSERT_TRUE(get.ok());
  EXPECT_EQ(get->status, 405);
  absl::StatusOr<HttpReply> elsewhere = HttpRequest(server_->http_port(), "GET", "/etc/passwd");
  ASSERT_TRUE(elsewhere.ok());
  EXPECT_EQ(elsewhere->status, 404);
  const HttpReply bad_timeout = Post("ListMaps", "{}", "", {"Grpc-Timeout: soon"});
  EXPECT_EQ(bad_timeout.status, 400);
  EXPECT_NE(ErrorOf(bad_timeout).message.find("Grpc-Timeout"), std::string::npos);
  // A deadline too short for a plan: DEADLINE_EXCEEDED or the best plan so
  // far, never a hang or a crash.
  v1::PutMapResponse stored;
  ASSERT_TRUE(stub_->PutMap(Ctx().get(), TwoRoomsMap(), &stored).ok());
  const HttpReply rushed =
      Post("Plan", Json(PlanRequestFor(stored.info().map_id(), 0.3)), "", {"Grpc-Timeout: 1m"});
  EXPECT_TRUE(rushed.status == 200 || rushed.status == 504) << rushed.status << rushed.body;
  // A deadline beyond a day is no client deadline (the server's bound holds).
  EXPECT_EQ(Post("ListMaps", "{}", "", {"Grpc-Timeout: 99999999H"}).status, 200);
  // Not JSON by its Content-Type (also what a cross-site form post sends).
  absl::StatusOr<HttpReply> form =
      HttpRequest(server_->http_port(), "POST", "/v1/ListMaps", {"Content-Type: text/plain"}, "{}");
  ASSERT_TRUE(form.ok());
  EXPECT_EQ(form->status, 415);
  // A body shorter than its Content-Length is not executed.
  absl::StatusOr<HttpReply> cut =
      HttpRequest(server_->http_port(), "POST", "/v1/ListMaps",
                  {"Content-Type: application/json", "Content-Length: 50"}, "{}");
  ASSERT_TRUE(cut.ok());
  EXPECT_NE(cut->status, 200);
}

TEST_F(HttpGatewayTest, TheConsoleIsServedFromTheSamePort) {
  Start();
  absl::StatusOr<HttpReply> page = HttpRequest(server_->http_port(), "GET", "/");
  ASSERT_TRUE(page.ok());
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->headers.find("text/html"), std::string::npos);
  EXPECT_NE(page->headers.find("Content-Security-Policy: default-src 'self'"), std::string::npos);
  EXPECT_NE(page->body.find("<script type=\"module\" src=\"/console.js\">"), std::string::npos);
  for (const char* asset : {"/console.js", "/console.css"}) {
    absl::StatusOr<HttpReply> r = HttpRequest(server_->http_port(), "GET", asset);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r->status, 200) << asset;
    EXPECT_GT(r->body.size(), 1000u) << asset;
  }
  absl::StatusOr<HttpReply> js = HttpRequest(server_->http_port(), "GET", "/console.js");
  EXPECT_NE(js->headers.find("text/javascript"), std::string::npos);
  EXPECT_NE(js->body.find("/v1/"), std::string::npos) << "the page calls the JSON API";
}

TEST_F(HttpGatewayTest, OversizedBodiesAreRefusedAndGrpcGoesOn) {
  Start(/*tokens=*/false, /*max_message_bytes=*/1 << 20);
  // Over the limit: 4/3 of gRPC's (base64) + 1 MiB.
  const std::string huge(3 << 20, ' ');
  const HttpReply r = Post("ListMaps", huge);
  EXPECT_EQ(r.status, 413);
  EXPECT_EQ(ErrorOf(r).code, grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(ErrorOf(r).message.find("limit"), std::string::npos);
  v1::ListMapsResponse list;
  EXPECT_TRUE(stub_->ListMaps(Ctx().get(), v1::ListMapsRequest(), &list).ok());
  EXPECT_EQ(Post("ListMaps", "{}").status, 200);
}

TEST_F(HttpGatewayTest, TokensAndTenantsAreGrpcs) {
  Start(/*tokens=*/true);
  const HttpReply anonymous = Post("ListMaps", "{}");
  EXPECT_EQ(anonymous.status, 401);
  EXPECT_EQ(ErrorOf(anonymous).code, grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(Post("ListMaps", "{}", "wrong-token").status, 401);

  const HttpReply put = Post("PutMap", Json(TwoRoomsMap()), kAlpha);
  ASSERT_EQ(put.status, 200) << put.body;
  v1::GetMapRequest get;
  get.set_map_id(FromJson<v1::PutMapResponse>(put.body).info().map_id());
  EXPECT_EQ(Post("GetMap", Json(get), kAlpha).status, 200);
  const HttpReply other = Post("GetMap", Json(get), kBeta);
  EXPECT_EQ(other.status, 404) << "another tenant's map is not found";
  EXPECT_EQ(ErrorOf(other).code, grpc::StatusCode::NOT_FOUND);
  const auto beta_list = FromJson<v1::ListMapsResponse>(Post("ListMaps", "{}", kBeta).body);
  EXPECT_EQ(beta_list.maps_size(), 0);
  // gRPC with alpha's token sees the map JSON stored.
  v1::GetMapResponse map;
  EXPECT_TRUE(stub_->GetMap(Ctx(kAlpha).get(), get, &map).ok());
}

// With tokens the door refuses a request without a valid one before its
// body is read: a body that is not JSON at all is 401, not 400 (which it is
// with alpha's token), and so is the event stream; the console's page,
// which asks for the token, stays open.
TEST_F(HttpGatewayTest, TheTokenIsCheckedAtTheDoorBeforeTheBody) {
  Start(/*tokens=*/true);
  const HttpReply anonymous = Post("PutMap", "this is not JSON");
  EXPECT_EQ(anonymous.status, 401) << anonymous.body;
  EXPECT_EQ(ErrorOf(anonymous).code, grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(ErrorOf(anonymous).message, ::testing::HasSubstr("Bearer"));
  EXPECT_EQ(Post("PutMap", "this is not JSON", "wrong-token").status, 401);
  EXPECT_EQ(Post("NoSuchMethod", "{}").status, 401) << "no method list for strangers";
  const HttpReply parsed = Post("PutMap", "this is not JSON", kAlpha);
  EXPECT_EQ(parsed.status, 400) << parsed.body;
  EXPECT_EQ(ErrorOf(parsed).code, grpc::StatusCode::INVALID_ARGUMENT);
  absl::StatusOr<HttpReply> events =
      HttpRequest(server_->http_port(), "GET", "/v1/events?map_id=m");
  ASSERT_TRUE(events.ok()) << events.status();
  EXPECT_EQ(events->status, 401);
  absl::StatusOr<HttpReply> page = HttpRequest(server_->http_port(), "GET", "/");
  ASSERT_TRUE(page.ok()) << page.status();
  EXPECT_EQ(page->status, 200);
}

// Connects and sends part of a request, then holds the connection.
int SlowClient(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) return -1;
  // A valid body ("{}") but 98 bytes short of its Content-Length: never
  // executed as it is.
  const std::string part =
      "POST /v1/ListMaps HTTP/1.1\r\nContent-Type: application/json\r\nContent-Length: "
      "100\r\n\r\n{}";
  ::send(fd, part.data(), part.size(), MSG_NOSIGNAL);
  return fd;
}

TEST_F(HttpGatewayTest, SlowClientsAreCutOffAndGrpcGoesOn) {
  Start(/*tokens=*/false, 80 << 20, /*request_timeout_ms=*/1000);
  std::vector<int> slow;
  for (int i = 0; i < 12; ++i) slow.push_back(SlowClient(server_->http_port()));
  // gRPC serves while every HTTP worker waits on a slow client.
  v1::PutMapResponse stored;
  ASSERT_TRUE(stub_->PutMap(Ctx().get(), TwoRoomsMap(), &stored).ok());
  v1::PlanResponse plan;
  EXPECT_TRUE(stub_->Plan(Ctx().get(), PlanRequestFor(stored.info().map_id(), 0.3), &plan).ok());
  // Each slow client is cut off (the server closes its side; the reply, if
  // any, is an error, never a success).
  for (int fd : slow) {
    ASSERT_GE(fd, 0);
    timeval timeout{20, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    std::string reply;
    char buf[4096];
    ssize_t n;
    while ((n = ::recv(fd, buf, sizeof(buf), 0)) > 0) reply.append(buf, static_cast<size_t>(n));
    EXPECT_EQ(n, 0) << "closed by the server, not by our 20 s timeout";
    EXPECT_EQ(reply.find(" 200 "), std::string::npos) << reply;
    ::close(fd);
  }
  // And the HTTP port serves again.
  EXPECT_EQ(Post("ListMaps", "{}").status, 200);
}

TEST(HttpGatewayConfig, TlsOnTheHttpPortIsRefusedClearly) {
  ServerConfig config;
  config.port = 0;
  config.metrics_port = -1;
  config.http_port = 0;
  config.tls_cert_file = "server.pem";
  config.tls_key_file = "server.key";
  absl::StatusOr<std::unique_ptr<CovplanServer>> server = CovplanServer::Start(config);
  ASSERT_FALSE(server.ok());
  EXPECT_EQ(server.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(server.status().message().find("--http_port"), std::string::npos);
}

}  // namespace
}  // namespace covplan
