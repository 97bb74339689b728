// vola view as a server on a real socket, against what a hostile client or web page
// sends: names other than its own in Host (DNS rebinding), bytes that are not UTF-8,
// oversized heads and bodies, slow clients, paths out of its files, and thousands of
// mutated requests. After each, the server must still answer a good request.
#include <gtest/gtest.h>

#include <random>
#include <thread>
#include <vector>

#include "raw_http.hpp"
#include "test_support.hpp"
#include "vola/builder.hpp"
#include "vola/file.hpp"
#include "vola/viewer/server.hpp"

namespace {

using namespace std::chrono_literals;
using vola_test::body_of;
using vola_test::RawConnection;
using vola_test::round_trip;
using vola_test::status_of;

// Short limits, so that the timeouts show within a test's time.
vola::viewer::ServerLimits test_limits() {
  vola::viewer::ServerLimits l;
  l.receive_timeout = 800ms;
  l.send_timeout = 2000ms;
  l.keep_alive_timeout = 500ms;
  l.workers = 4;
  l.max_waiting_connections = 4;
  return l;
}

// A small .vol in a temporary directory, served on a free port of 127.0.0.1.
class ServedFile : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::vector<vola::Voxel> voxels{{1, 2, 3}, {40, 41, 42}, {63, 0, 7}};
    const vola::Tree tree = vola::build_from_voxels(voxels, 3);
    path_ = (dir_ / "scene.vol").string();
    vola::write(tree, path_);
    std::vector<std::unique_ptr<vola::viewer::ViewedFile>> files;
    files.push_back(std::make_unique<vola::viewer::ViewedFile>(path_));
    vola::viewer::ServerOptions options;
    options.limits = test_limits();
    server_ = std::make_unique<vola::viewer::Server>(std::move(files), options);
    port_ = server_->bind();
    thread_ = std::thread([this] { server_->listen(); });
  }
  void TearDown() override {
    server_->stop();
    thread_.join();
  }

  std::string host() const { return "127.0.0.1:" + std::to_string(port_); }
  std::string get(const std::string& target, const std::string& host_header) const {
    return round_trip(port_, "GET " + target + " HTTP/1.1\r\nHost: " + host_header + "\r\nConnection: close\r\n\r\n");
  }
  std::string get(const std::string& target) const { return get(target, host()); }
  void expect_alive() const {
    const std::string answer = get("/api/files");
    ASSERT_EQ(status_of(answer), 200) << answer;
    EXPECT_NE(body_of(answer).find("\"scene.vol\""), std::string::npos);
  }

  vola_test::TempDir dir_;
  std::string path_;
  std::unique_ptr<vola::viewer::Server> server_;
  int port_ = 0;
  std::thread thread_;
};

TEST_F(ServedFile, BytesThatAreNotUtf8Get400AndTheServerLives) {
  for (const char* target :
       {"/%ff", "/%c0%af", "/api/files/0/cell?level=%ff&x=0&y=0&z=0", "/%ed%a0%80", "/%f4%90%80%80"}) {
    const std::string answer = get(target);
    EXPECT_EQ(status_of(answer), 400) << target << "\n" << answer;
  }
  expect_alive();
}

// A second viewer on the port of a running one is refused (httplib's SO_REUSEPORT let it
// bind, and the kernel split the requests between the two).
TEST_F(ServedFile, ASecondServerCannotTakeItsPort) {
  std::vector<std::unique_ptr<vola::viewer::ViewedFile>> files;
  files.push_back(std::make_unique<vola::viewer::ViewedFile>(path_));
  vola::viewer::ServerOptions options;
  options.limits = test_limits();
  options.port = port_;
  vola::viewer::Server second(std::move(files), options);
  EXPECT_THROW(second.bind(), vola::IoError);
  expect_alive();
}

TEST_F(ServedFile, OnlyItsOwnNamesInHostAreAnswered) {
  const std::string port = std::to_string(port_);
  const std::vector<std::string> foreign{
      "evil.example:" + port,           "evil.example",           "127.0.0.1:" + std::to_string(port_ + 1), "127.0.0.1",
      "localhost.evil.example:" + port, "127.0.0.1:" + port + "0"};
  for (const std::string& name : foreign) {
    const std::string answer = get("/api/files", name);
    EXPECT_EQ(status_of(answer), 403) << name << "\n" << answer;
    EXPECT_EQ(body_of(answer).find("scene.vol"), std::string::npos) << name;
  }
  for (const std::string& name :
       std::vector<std::string>{"localhost:" + port, "LocalHost:" + port, "127.0.0.1:" + port, "[::1]:" + port})
    EXPECT_EQ(status_of(get("/api/files", name)), 200) << name;
  EXPECT_EQ(status_of(round_trip(port_, "GET /api/files HTTP/1.1\r\n\r\n")), 400);
  EXPECT_EQ(
      status_of(round_trip(port_, "GET /api/files HTTP/1.1\r\nHost: " + host() + "\r\nHost: evil.example\r\n\r\n")),
      400);
  expect_alive();
}

TEST_F(ServedFile, AHeadOverTheLimitGets431) {
  std::string many = "GET /api/files HTTP/1.1\r\nHost: " + host() + "\r\n";
  for (int i = 0; i < 4000; ++i) many += "X-Filler-" + std::to_string(i) + ": some value\r\n";
  EXPECT_EQ(status_of(round_trip(port_, many + "\r\n")), 431);
  // One endless header line: httplib alone would keep it all in memory.
  RawConnection endless(port_);
  endless.send("GET / HTTP/1.1\r\nHost: " + host() + "\r\nX-Long: ");
  const std::string filler(1 << 16, 'a');
  for (int i = 0; i < 64 && !endless.closed(); ++i) endless.send(filler);
  EXPECT_EQ(status_of(endless.receive_all()), 431);
  expect_alive();
}

TEST_F(ServedFile, ABodyOverTheLimitGets413) {
  const std::string body_bytes(256 * 1024, 'b');
  RawConnection declared(port_);
  declared.send("POST /api/files HTTP/1.1\r\nHost: " + host() + "\r\nContent-Length: 1073741824\r\n\r\n");
  declared.send(body_bytes);
  EXPECT_EQ(status_of(declared.receive_all()), 413);
  RawConnection chunked(port_);
  chunked.send("POST /api/files HTTP/1.1\r\nHost: " + host() + "\r\nTransfer-Encoding: chunked\r\n\r\n");
  for (int i = 0; i < 8; ++i) chunked.send("8000\r\n" + std::string(0x8000, 'c') + "\r\n");
  EXPECT_EQ(status_of(chunked.receive_all()), 413);
  expect_alive();
}

TEST_F(ServedFile, ASlowClientIsCutAtTheReceiveTimeoutNotPerByte) {
  RawConnection slow(port_);
  slow.send("GET /api/files HTTP/1.1\r\n");
  const auto start = std::chrono::steady_clock::now();
  std::string answer;
  // One header byte every 100 ms: each read is quick, the request never ends.
  for (int i = 0; i < 40 && answer.empty(); ++i) {
    slow.send("X");
    answer = slow.receive_all(100ms);
  }
  answer += slow.receive_all(1000ms);
  EXPECT_EQ(status_of(answer), 408) << answer;
  EXPECT_LT(std::chrono::steady_clock::now() - start, 2000ms);
  expect_alive();
}

TEST_F(ServedFile, SlowClientsCannotHoldTheServer) {
  // More stalled clients than workers and waiting places together: the extra ones are
  // turned away at once (503), the others cut at the receive timeout (408).
  std::vector<std::unique_ptr<RawConnection>> stalled;
  for (int i = 0; i < 16; ++i) {
    stalled.push_back(std::make_unique<RawConnection>(port_));
    stalled.back()->send("GET /api/files HTTP/1.1\r\nHost: " + host() + "\r\n");
  }
  // A good client that retries when turned away is served within a few receive timeouts.
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  while (status != 200 && std::chrono::steady_clock::now() - start < 6000ms) {
    status = status_of(get("/api/files"));
    ASSERT_TRUE(status == 200 || status == 503) << status;
  }
  EXPECT_EQ(status, 200);
  // (httplib's own pool held each stalled client for 5 s per read: 10 s and more here.)
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5000ms);
  int timed_out = 0, busy = 0;
  for (auto& c : stalled) {
    const std::string answer = c->receive_all(3000ms);
    EXPECT_TRUE(c->closed());
    timed_out += status_of(answer) == 408;
    busy += status_of(answer) == 503;
  }
  EXPECT_EQ(timed_out + busy, 16);
  EXPECT_GT(busy, 0);
}

TEST_F(ServedFile, NoPathItWasGivenAndNoFileOutsideItsOwn) {
  const std::string files = get("/api/files");
  ASSERT_EQ(status_of(files), 200);
  EXPECT_EQ(files.find(dir_.path().string()), std::string::npos) << files;
  const std::string bad_level = get("/api/files/0/cell?level=9&x=0&y=0&z=0");
  EXPECT_EQ(status_of(bad_level), 400);
  EXPECT_EQ(bad_level.find(dir_.path().string()), std::string::npos) << bad_level;
  for (const char* target :
       {"/../../../../etc/passwd", "/%2e%2e/%2e%2e/%2e%2e/etc/passwd", "/viewer.js/../../etc/passwd",
        "/api/files/0/..%2f..%2f..%2fetc%2fpasswd", "//etc/passwd", "/api/files/1/cells?level=0", "/api/files/-1/cell",
        "/etc/passwd", "/scene.vol", "/api/files/0/../../scene.vol"}) {
    const std::string answer = get(target);
    EXPECT_TRUE(status_of(answer) == 404 || status_of(answer) == 400) << target << "\n" << answer;
    EXPECT_EQ(answer.find("root:"), std::string::npos) << target;
    EXPECT_EQ(answer.find("VOL"), std::string::npos) << target;
  }
  expect_alive();
}

TEST_F(ServedFile, PipelinedRequestsAreAnsweredInOrderAndAnErrorClosesTheConnection) {
  const std::string one = "GET /api/files HTTP/1.1\r\nHost: " + host() + "\r\n\r\n";
  const std::string answers =
      round_trip(port_, one + one + "GET /nothing HTTP/1.1\r\nHost: " + host() + "\r\n\r\n" + one);
  std::vector<int> statuses;
  for (std::size_t at = answers.find("HTTP/1.1 "); at != std::string::npos; at = answers.find("HTTP/1.1 ", at + 1))
    statuses.push_back(status_of(std::string_view(answers).substr(at)));
  EXPECT_EQ(statuses, (std::vector<int>{200, 200, 404}));
}

// Requests the fuzz loop starts from: every route, and the hostile ones above.
std::vector<std::string> seed_requests(const std::string& host) {
  const std::string h = "\r\nHost: " + host + "\r\n";
  return {"GET / HTTP/1.1" + h + "\r\n",
          "GET /api/files HTTP/1.1" + h + "Connection: keep-alive\r\n\r\n",
          "GET /api/files/0/cells?level=1&first=0&count=10 HTTP/1.1" + h + "\r\n",
          "GET /api/files/0/cell?level=2&x=1&y=2&z=3 HTTP/1.1" + h + "\r\n",
          "GET /api/files/0/pick?level=2&ox=-1&oy=0.5&oz=0.5&dx=1&dy=0&dz=0&tmax=100 HTTP/1.1" + h + "\r\n",
          "GET /%ff HTTP/1.1" + h + "\r\n",
          "POST /api/files HTTP/1.1" + h + "Content-Length: 5\r\n\r\nhello",
          "POST /api/files HTTP/1.1" + h + "Transfer-Encoding: chunked\r\n\r\n5\r\nhello\r\n0\r\n\r\n",
          "GET /api/files HTTP/1.1" + h + "Range: bytes=0-10,20-30\r\nExpect: 100-continue\r\n\r\n",
          "GET /api/files HTTP/1.0\r\n\r\n"};
}

std::string mutate(std::string s, std::mt19937_64& rng, const std::vector<std::string>& seeds) {
  static const std::string tokens[] = {"\r\n",
                                       "\r\n\r\n",
                                       "%",
                                       "%ff",
                                       "%00",
                                       "\n",
                                       ":",
                                       "..",
                                       "/",
                                       "?",
                                       "&",
                                       "=",
                                       "Content-Length: 99999999999999999999\r\n",
                                       "Transfer-Encoding: chunked\r\n",
                                       "Range: bytes=-1\r\n",
                                       "Host: evil\r\n",
                                       std::string(300, 'A'),
                                       "\xff\xfe"};
  const int edits = 1 + static_cast<int>(rng() % 6);
  for (int e = 0; e < edits; ++e) {
    const std::size_t at = s.empty() ? 0 : rng() % (s.size() + 1);
    switch (rng() % 6) {
      case 0:
        if (at < s.size()) s[at] = static_cast<char>(rng());
        break;
      case 1:
        s.insert(at, tokens[rng() % std::size(tokens)]);
        break;
      case 2:
        s.erase(at, rng() % 16);
        break;
      case 3:
        s.insert(at, std::string(1 + rng() % 8, static_cast<char>(rng())));
        break;
      case 4:
        s += seeds[rng() % seeds.size()];
        break;  // pipelined
      default:
        s.resize(at);
        break;  // cut short
    }
  }
  return s;
}

TEST_F(ServedFile, SurvivesThousandsOfMutatedRequests) {
  std::mt19937_64 rng(2024);
  const auto seeds = seed_requests(host());
  std::vector<int> statuses(600, 0);
  for (int i = 0; i < 3000; ++i) {
    const std::string request = mutate(seeds[rng() % seeds.size()], rng, seeds);
    const std::string answer = round_trip(port_, request);
    // Nothing, when the request line never came; otherwise an answer with a status line.
    ASSERT_TRUE(answer.empty() || (status_of(answer) >= 100 && status_of(answer) < 600)) << request << "\n" << answer;
    ASSERT_NE(status_of(answer), 500) << request << "\n" << answer;
    ++statuses[static_cast<std::size_t>(status_of(answer))];
  }
  EXPECT_GT(statuses[200], 0);
  EXPECT_GT(statuses[403], 0);
  EXPECT_GT(statuses[400] + statuses[404], 0);
  expect_alive();
}

TEST_F(ServedFile, RespondAnswersMemoryBytesAsASocket) {
  std::mt19937_64 rng(99);
  const auto seeds = seed_requests(host());
  EXPECT_EQ(status_of(server_->respond(seeds[1])), 200);
  EXPECT_EQ(status_of(server_->respond("GET /%ff HTTP/1.1\r\nHost: " + host() + "\r\n\r\n")), 400);
  for (int i = 0; i < 20000; ++i) {
    const std::string request = mutate(seeds[rng() % seeds.size()], rng, seeds);
    const std::string answer = server_->respond(request);
    ASSERT_TRUE(answer.empty() || status_of(answer) >= 100) << request;
    ASSERT_NE(status_of(answer), 500) << request << "\n" << answer;
  }
  expect_alive();
}

}  // namespace
