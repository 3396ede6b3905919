// Run traces: round trip, truncated files, malformed files, flush period, full rings.
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstring>
#include <iterator>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "gauss6/trace.h"

using namespace gauss6;
namespace fs = std::filesystem;

namespace {

fs::path temp_path(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "gauss6_device_tests";
  fs::create_directories(dir);
  return dir / name;
}

// A tick whose every field depends on i, so that a swapped or shifted column shows.
TraceTick make_tick(int i) {
  TraceTick t;
  t.t = i * 1e-3;
  t.X_WH.p = Vec3(i / 3.0, -i / 7.0, 0.1 * i);
  t.X_WH.q = normalized(Quat{1.0, 0.01 * i, -0.02 * i, 0.003 * i});
  t.X_WS.p = Vec3(1.0 / (i + 1), 2.0, -3.0 * i);
  t.X_WS.q = normalized(Quat{0.5, 0.5, 0.5 + 0.001 * i, 0.5});
  for (int k = 0; k < 6; ++k) t.F[k] = (k + 1) * std::sin(0.1 * i);
  t.num_contacts = i % 5;
  t.force_time = 1e-6 * (1 + i % 3);
  t.status = (i % 11 == 0) ? DeviceStatus::kTimeout : DeviceStatus::kOk;
  t.flags = kTickGripped | ((i % 2) ? kTickNewContactSet : 0u);
  t.buttons = static_cast<uint32_t>(i % 4);
  return t;
}

TraceMeta make_meta() {
  TraceMeta m;
  m.scene = "peg_in_hole";
  m.device = "simulated";
  m.device_rate_hz = 1000;
  m.phases = {{"a", 0.0}, {"b", 0.5}};
  m.extra_json = R"({"ks": 0.5})";
  return m;
}

void write_sample(const fs::path& path, int num_ticks, int num_steps) {
  TraceWriterSettings s;
  s.background_thread = false;
  s.rows_per_chunk = 100;  // several chunks per stream
  TraceWriter w(path.string(), make_meta(), s);
  for (int i = 0; i < num_ticks; ++i) REQUIRE(w.append(make_tick(i)));
  for (int k = 0; k < num_steps; ++k) {
    REQUIRE(w.append(TraceStep{static_cast<uint64_t>(k), 0.01 * k, 1e-4 * k, 2, 0}));
    for (int c = 0; c < 2; ++c)
      REQUIRE(w.append(TraceContact{static_cast<uint64_t>(k), 0.01 * k, Vec3(k, c, 1), Vec3(0, 0, 1), 1e-5 * c}));
  }
  REQUIRE(w.append(TraceEvent{0.5, TraceEventCode::kPhase, 1}));
  REQUIRE(w.append(TraceEvent{0.7, TraceEventCode::kLetGo, 0}));
  w.close();
}

}  // namespace

TEST_CASE("trace round trip: every row and field comes back bit-exact", "[trace]") {
  const fs::path path = temp_path("roundtrip.g6trace");
  write_sample(path, 1234, 50);
  const Trace tr = read_trace(path.string());
  CHECK(tr.version == kTraceVersion);
  CHECK(tr.complete);
  CHECK(tr.warnings.empty());
  REQUIRE(tr.ticks.num_rows() == 1234);
  REQUIRE(tr.steps.num_rows() == 50);
  REQUIRE(tr.contacts.num_rows() == 100);
  REQUIRE(tr.events.num_rows() == 2);
  for (int i = 0; i < 1234; ++i) {
    const TraceTick a = make_tick(i), b = trace_tick(tr, i);
    // Doubles are stored as they are: exact equality, no tolerance.
    CHECK(a.t == b.t);
    CHECK(a.X_WH.p == b.X_WH.p);
    CHECK((a.X_WH.q.w == b.X_WH.q.w && a.X_WH.q.x == b.X_WH.q.x && a.X_WH.q.y == b.X_WH.q.y && a.X_WH.q.z == b.X_WH.q.z));
    CHECK(a.X_WS.p == b.X_WS.p);
    CHECK(a.X_WS.q.z == b.X_WS.q.z);
    CHECK(a.F == b.F);
    CHECK(a.num_contacts == b.num_contacts);
    CHECK(a.force_time == b.force_time);
    CHECK(a.status == b.status);
    CHECK(a.flags == b.flags);
    CHECK(a.buttons == b.buttons);
  }
  CHECK(tr.contacts.row(7)[2] == 3.0);   // step 3, contact 1: point (3, 1, 1)
  CHECK(tr.contacts.row(7)[3] == 1.0);
  CHECK(tr.events.row(1)[1] == static_cast<double>(TraceEventCode::kLetGo));
  const auto meta = nlohmann::json::parse(tr.meta_json);
  CHECK(meta["format"] == "gauss6-trace");
  CHECK(meta["version"] == kTraceVersion);
  CHECK(meta["scene"] == "peg_in_hole");
  CHECK(meta["phases"][1]["name"] == "b");
  CHECK(meta["extra"]["ks"] == 0.5);
  CHECK(meta["columns"]["ticks"].size() == trace_columns(TraceChunk::kTicks).size());
  CHECK(meta["machine"]["cores"].get<int>() >= 1);
}

TEST_CASE("version 1 traces stay readable: steps without update_cpu_time read it as NaN", "[trace]") {
  const fs::path path = temp_path("v2.g6trace");
  {
    TraceWriter w(path.string(), TraceMeta{}, TraceWriterSettings{});
    TraceStep st;
    st.step = 4;
    st.update_time = 2e-4;
    st.num_contacts = 3;
    st.update_cpu_time = 1.5e-4;
    REQUIRE(w.append(st));
    w.close();
  }
  const Trace now = read_trace(path.string());
  REQUIRE(now.steps.num_rows() == 1);
  CHECK(now.steps.row(0)[5] == 1.5e-4);
  // Rewritten as version 1: header version 1, the steps' rows without their last value.
  std::ifstream in(path, std::ios::binary);
  const std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  uint64_t meta_len = 0;
  std::memcpy(&meta_len, b.data() + 16, 8);
  std::string out = b.substr(0, 24 + meta_len);
  const uint32_t v1 = 1;
  std::memcpy(out.data() + 8, &v1, 4);
  for (size_t pos = 24 + meta_len; pos + 16 <= b.size();) {
    uint32_t type = 0, cols = 0;
    uint64_t rows = 0;
    std::memcpy(&type, b.data() + pos, 4);
    std::memcpy(&cols, b.data() + pos + 4, 4);
    std::memcpy(&rows, b.data() + pos + 8, 8);
    const uint32_t keep = type == static_cast<uint32_t>(TraceChunk::kSteps) ? cols - 1 : cols;
    std::string head = b.substr(pos, 16);
    std::memcpy(head.data() + 4, &keep, 4);
    out += head;
    for (uint64_t r = 0; r < rows; ++r) out += b.substr(pos + 16 + r * cols * 8, keep * 8);
    pos += 16 + rows * cols * 8;
  }
  const fs::path old = temp_path("v1.g6trace");
  std::ofstream(old, std::ios::binary) << out;
  const Trace tr = read_trace(old.string());
  CHECK(tr.version == 1);
  REQUIRE(tr.steps.num_cols == kStepCols);
  REQUIRE(tr.steps.num_rows() == 1);
  CHECK(tr.steps.row(0)[0] == 4.0);
  CHECK(tr.steps.row(0)[2] == 2e-4);
  CHECK(tr.steps.row(0)[3] == 3.0);
  CHECK(std::isnan(tr.steps.row(0)[5]));
}

TEST_CASE("trace cut mid-chunk reads up to the last complete chunk, with a warning", "[trace]") {
  const fs::path path = temp_path("cut.g6trace");
  write_sample(path, 1000, 0);  // tick chunks of 100 rows: 10 chunks, then events and end
  const auto full = fs::file_size(path);
  const Trace whole = read_trace(path.string());
  // Header size: from the first tick chunk's offset; cut 3 rows into the 6th tick chunk.
  const size_t chunk_bytes = 16 + 100 * kTickCols * 8;
  const size_t header = 24 + whole.meta_json.size();
  const size_t cut = header + 5 * chunk_bytes + 16 + 3 * kTickCols * 8 + 5;
  REQUIRE(cut < full);
  fs::resize_file(path, cut);
  const Trace tr = read_trace(path.string());
  CHECK_FALSE(tr.complete);
  CHECK(tr.ticks.num_rows() == 500);
  REQUIRE(tr.warnings.size() == 1);
  CHECK_THAT(tr.warnings[0], Catch::Contains("cut mid-chunk"));
  CHECK_THAT(tr.warnings[0], Catch::Contains("cut.g6trace"));

  // Cut inside a chunk header: the same, with the chunks before it.
  fs::resize_file(path, header + 2 * chunk_bytes + 9);
  const Trace tr2 = read_trace(path.string());
  CHECK(tr2.ticks.num_rows() == 200);
  CHECK(tr2.warnings.size() == 1);
}

TEST_CASE("malformed traces give an error naming the file and the problem", "[trace]") {
  const fs::path good = temp_path("good.g6trace");
  write_sample(good, 10, 1);
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  auto write_bytes = [](const fs::path& p, const std::string& b) {
    std::ofstream out(p, std::ios::binary);
    out.write(b.data(), static_cast<std::streamsize>(b.size()));
  };
  const fs::path bad = temp_path("bad.g6trace");

  std::string b = bytes;
  b[0] = 'X';
  write_bytes(bad, b);
  CHECK_THROWS_WITH(read_trace(bad.string()), Catch::Contains("bad.g6trace") && Catch::Contains("bad magic"));

  b = bytes;
  b[8] = 99;  // version
  write_bytes(bad, b);
  CHECK_THROWS_WITH(read_trace(bad.string()), Catch::Contains("unsupported trace version 99"));

  b = bytes;
  b[16] = static_cast<char>(0xff), b[17] = static_cast<char>(0xff), b[18] = static_cast<char>(0xff);
  write_bytes(bad, b);
  CHECK_THROWS_WITH(read_trace(bad.string()), Catch::Contains("metadata block"));

  b = bytes;
  b[24] = '#';  // the JSON's opening brace
  write_bytes(bad, b);
  CHECK_THROWS_WITH(read_trace(bad.string()), Catch::Contains("not valid JSON"));

  b = bytes;
  uint64_t meta_len = 0;
  std::memcpy(&meta_len, b.data() + 16, 8);
  b[24 + meta_len + 4] = 7;  // first chunk's row width
  write_bytes(bad, b);
  CHECK_THROWS_WITH(read_trace(bad.string()), Catch::Contains("rows of 7 values, expected 26"));

  write_bytes(bad, "hello");
  CHECK_THROWS_WITH(read_trace(bad.string()), Catch::Contains("shorter than the header"));
  CHECK_THROWS_WITH(read_trace(temp_path("absent.g6trace").string()), Catch::Contains("cannot open"));
}

TEST_CASE("the flush thread makes rows visible within the flush period", "[trace]") {
  const fs::path path = temp_path("flush.g6trace");
  TraceWriterSettings s;
  s.flush_period = 0.05;
  TraceWriter w(path.string(), make_meta(), s);
  for (int i = 0; i < 100; ++i) REQUIRE(w.append(make_tick(i)));
  // Without close(): a reader sees the rows once the thread has flushed (a crash
  // now would lose nothing). Allow 20 periods for a loaded machine.
  size_t seen = 0;
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < std::chrono::seconds(1)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    seen = read_trace(path.string()).ticks.num_rows();
    if (seen == 100) break;
  }
  CHECK(seen == 100);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK(waited < 20 * s.flush_period);
  CHECK(w.stats().num_flushes >= 1);
  w.close();
  const Trace tr = read_trace(path.string());
  CHECK(tr.complete);
  CHECK(tr.ticks.num_rows() == 100);
  CHECK_THROWS_AS(TraceWriter(temp_path("x.g6trace").string(), make_meta(), TraceWriterSettings{2.0}), TraceError);
}

TEST_CASE("a full ring drops rows, counts them and the end chunk records them", "[trace]") {
  const fs::path path = temp_path("full.g6trace");
  TraceWriterSettings s;
  s.background_thread = false;
  s.tick_capacity = 16;
  TraceWriter w(path.string(), make_meta(), s);
  int accepted = 0;
  for (int i = 0; i < 20; ++i) accepted += w.append(make_tick(i)) ? 1 : 0;
  CHECK(accepted == 16);
  w.flush();  // frees the ring
  CHECK(w.append(make_tick(20)));
  w.close();
  const Trace tr = read_trace(path.string());
  CHECK(tr.ticks.num_rows() == 17);
  CHECK(tr.dropped[0] == 4);
  CHECK(trace_tick(tr, 16).t == make_tick(20).t);
}

TEST_CASE("concurrent producers lose no row", "[trace]") {
  const fs::path path = temp_path("mp.g6trace");
  TraceWriterSettings s;
  s.flush_period = 0.01;
  s.event_capacity = 1u << 14;
  {
    TraceWriter w(path.string(), make_meta(), s);
    auto produce = [&w](int offset) {
      for (int i = 0; i < 5000; ++i) {
        while (!w.append(TraceEvent{double(offset + i), TraceEventCode::kWatchdog, 0})) std::this_thread::yield();
      }
    };
    std::thread a(produce, 0), b(produce, 100000);
    a.join();
    b.join();
    w.close();
  }
  const Trace tr = read_trace(path.string());
  REQUIRE(tr.events.num_rows() == 10000);
  // Each producer's rows arrive complete and in its own order.
  std::vector<double> ta, tb;
  for (size_t i = 0; i < tr.events.num_rows(); ++i) {
    const double t = tr.events.row(i)[0];
    (t < 100000 ? ta : tb).push_back(t);
  }
  REQUIRE(ta.size() == 5000);
  REQUIRE(tb.size() == 5000);
  for (int i = 0; i < 5000; ++i) {
    CHECK(ta[i] == i);
    CHECK(tb[i] == 100000 + i);
  }
}
