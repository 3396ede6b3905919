// Run traces: the lock-free row rings, the chunk writer and its flush thread,
// and the reader (docs/trace-format.md).
#include "gauss6/trace.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <atomic>
#include <bit>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <limits>
#include <ctime>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

namespace gauss6 {

static_assert(std::endian::native == std::endian::little, "the trace writer stores native doubles: little-endian only");
static_assert(sizeof(double) == 8);

const char* to_string(TraceEventCode c) {
  switch (c) {
    case TraceEventCode::kPhase: return "phase";
    case TraceEventCode::kLetGo: return "let_go";
    case TraceEventCode::kWatchdog: return "watchdog";
    case TraceEventCode::kDeviceLost: return "device_lost";
    case TraceEventCode::kDeviceReconnected: return "device_reconnected";
    case TraceEventCode::kDeviceEnded: return "device_ended";
  }
  return "unknown";
}

const std::vector<TraceColumn>& trace_columns(TraceChunk chunk) {
  static const std::vector<TraceColumn> ticks = {
      {"t", 1}, {"xh_p", 3}, {"xh_q", 4}, {"xs_p", 3}, {"xs_q", 4}, {"wrench", 6},
      {"num_contacts", 1}, {"force_time", 1}, {"status", 1}, {"flags", 1}, {"buttons", 1}};
  static const std::vector<TraceColumn> steps = {
      {"step", 1}, {"t", 1}, {"update_time", 1}, {"num_contacts", 1}, {"status", 1}, {"update_cpu_time", 1}};
  static const std::vector<TraceColumn> contacts = {
      {"step", 1}, {"t", 1}, {"point", 3}, {"normal", 3}, {"separation", 1}};
  static const std::vector<TraceColumn> events = {{"t", 1}, {"code", 1}, {"value", 1}};
  static const std::vector<TraceColumn> end = {
      {"dropped_ticks", 1}, {"dropped_steps", 1}, {"dropped_contacts", 1}, {"dropped_events", 1}};
  switch (chunk) {
    case TraceChunk::kTicks: return ticks;
    case TraceChunk::kSteps: return steps;
    case TraceChunk::kContacts: return contacts;
    case TraceChunk::kEvents: return events;
    case TraceChunk::kEnd: return end;
  }
  return end;
}

namespace {

// Row width of a known chunk type in a file of the given version; 0 for an unknown type.
size_t expected_cols(uint32_t type, uint32_t version) {
  switch (static_cast<TraceChunk>(type)) {
    case TraceChunk::kTicks: return kTickCols;
    case TraceChunk::kSteps: return version == 1 ? kStepColsV1 : kStepCols;
    case TraceChunk::kContacts: return kContactCols;
    case TraceChunk::kEvents: return kEventCols;
    case TraceChunk::kEnd: return kEndCols;
  }
  return 0;
}

// A bounded multi-producer multi-consumer queue of fixed-width rows (Vyukov's
// sequence-numbered ring): every cell carries a sequence number telling whether
// it is free for the producer of ticket k or full for the consumer of ticket k.
// Memory is allocated once; push and pop are lock-free and allocation-free.
class RowRing {
 public:
  RowRing(size_t capacity, size_t num_cols)
      : capacity_(std::bit_ceil(std::max<size_t>(capacity, 2))),
        num_cols_(num_cols),
        seq_(new std::atomic<size_t>[capacity_]),
        data_(capacity_ * num_cols, 0.0) {
    for (size_t i = 0; i < capacity_; ++i) seq_[i].store(i, std::memory_order_relaxed);
  }

  bool push(const double* row) noexcept {
    size_t pos = head_.load(std::memory_order_relaxed);
    for (;;) {
      std::atomic<size_t>& seq = seq_[pos & (capacity_ - 1)];
      const size_t s = seq.load(std::memory_order_acquire);
      const intptr_t diff = static_cast<intptr_t>(s) - static_cast<intptr_t>(pos);
      if (diff == 0) {
        // The cell is free for ticket pos: claim it, then fill it and publish it.
        if (head_.compare_exchange_weak(pos, pos + 1, std::memory_order_relaxed)) {
          std::memcpy(&data_[(pos & (capacity_ - 1)) * num_cols_], row, num_cols_ * sizeof(double));
          seq.store(pos + 1, std::memory_order_release);
          return true;
        }
      } else if (diff < 0) {
        return false;  // full: the consumer has not freed this cell yet
      } else {
        pos = head_.load(std::memory_order_relaxed);
      }
    }
  }

  bool pop(double* row) noexcept {
    size_t pos = tail_.load(std::memory_order_relaxed);
    for (;;) {
      std::atomic<size_t>& seq = seq_[pos & (capacity_ - 1)];
      const size_t s = seq.load(std::memory_order_acquire);
      const intptr_t diff = static_cast<intptr_t>(s) - static_cast<intptr_t>(pos + 1);
      if (diff == 0) {
        if (tail_.compare_exchange_weak(pos, pos + 1, std::memory_order_relaxed)) {
          std::memcpy(row, &data_[(pos & (capacity_ - 1)) * num_cols_], num_cols_ * sizeof(double));
          seq.store(pos + capacity_, std::memory_order_release);
          return true;
        }
      } else if (diff < 0) {
        return false;  // empty
      } else {
        pos = tail_.load(std::memory_order_relaxed);
      }
    }
  }

  size_t num_cols() const { return num_cols_; }

 private:
  const size_t capacity_;
  const size_t num_cols_;
  std::unique_ptr<std::atomic<size_t>[]> seq_;
  std::vector<double> data_;
  alignas(64) std::atomic<size_t> head_{0};
  alignas(64) std::atomic<size_t> tail_{0};
};

std::string utc_now_iso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

nlohmann::json machine_json() {
  nlohmann::json m;
  char host[256] = {0};
  m["hostname"] = gethostname(host, sizeof host - 1) == 0 ? std::string(host) : std::string();
  std::string cpu;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) cpu = line.substr(std::min(colon + 2, line.size()));
      break;
    }
  }
  m["cpu"] = cpu;
  m["cores"] = std::thread::hardware_concurrency();
#if defined(__VERSION__)
  m["compiler"] = __VERSION__;
#endif
  return m;
}

nlohmann::json columns_json() {
  nlohmann::json c;
  const std::pair<const char*, TraceChunk> streams[] = {{"ticks", TraceChunk::kTicks},
                                                        {"steps", TraceChunk::kSteps},
                                                        {"contacts", TraceChunk::kContacts},
                                                        {"events", TraceChunk::kEvents},
                                                        {"end", TraceChunk::kEnd}};
  for (const auto& [name, chunk] : streams) {
    nlohmann::json cols = nlohmann::json::array();
    for (const TraceColumn& col : trace_columns(chunk)) cols.push_back({col.name, col.width});
    c[name] = cols;
  }
  return c;
}

void put_pose(double* out, const Pose& x) {
  out[0] = x.p.x(), out[1] = x.p.y(), out[2] = x.p.z();
  out[3] = x.q.w, out[4] = x.q.x, out[5] = x.q.y, out[6] = x.q.z;
}

Pose get_pose(const double* in) { return {Vec3(in[0], in[1], in[2]), Quat{in[3], in[4], in[5], in[6]}}; }

// v is an integer in [lo, hi] (false for NaN and infinities): the reader's check
// before a value from the file is cast to an integer type.
bool integer_in(double v, double lo, double hi) { return v >= lo && v <= hi && std::trunc(v) == v; }

constexpr double kMaxCount = 9007199254740992.0;  // 2^53: every count a double holds exactly

// The integer columns of every row, checked once at read time so that trace_tick()
// and the replay device cast only in-range values. Empty when all are valid.
std::string check_integer_columns(const Trace& tr) {
  auto bad = [](const char* stream, size_t row, const char* column, double v) {
    return std::string(stream) + " row " + std::to_string(row) + ": " + column + " = " + std::to_string(v) +
           " is not an integer in range";
  };
  for (size_t i = 0; i < tr.ticks.num_rows(); ++i) {
    const double* r = tr.ticks.row(i);
    if (!std::isfinite(r[0])) return bad("ticks", i, "t", r[0]);
    if (!integer_in(r[21], 0, 2147483647.0)) return bad("ticks", i, "num_contacts", r[21]);
    if (!integer_in(r[23], 0, static_cast<double>(DeviceStatus::kError))) return bad("ticks", i, "status", r[23]);
    if (!integer_in(r[24], 0, 4294967295.0)) return bad("ticks", i, "flags", r[24]);
    if (!integer_in(r[25], 0, 4294967295.0)) return bad("ticks", i, "buttons", r[25]);
  }
  for (size_t i = 0; i < tr.steps.num_rows(); ++i) {
    const double* r = tr.steps.row(i);
    if (!integer_in(r[0], 0, kMaxCount)) return bad("steps", i, "step", r[0]);
    if (!integer_in(r[3], 0, 2147483647.0)) return bad("steps", i, "num_contacts", r[3]);
    if (!integer_in(r[4], -2147483648.0, 2147483647.0)) return bad("steps", i, "status", r[4]);
  }
  for (size_t i = 0; i < tr.contacts.num_rows(); ++i)
    if (!integer_in(tr.contacts.row(i)[0], 0, kMaxCount)) return bad("contacts", i, "step", tr.contacts.row(i)[0]);
  for (size_t i = 0; i < tr.events.num_rows(); ++i)
    if (!integer_in(tr.events.row(i)[1], 0, 4294967295.0)) return bad("events", i, "code", tr.events.row(i)[1]);
  return {};
}

}  // namespace

struct TraceWriter::Impl {
  std::string path;
  TraceWriterSettings settings;
  std::FILE* file = nullptr;
  // One ring per stream, indexed like TraceWriterStats (ticks, steps, contacts, events).
  std::array<std::unique_ptr<RowRing>, 4> rings;
  std::array<std::atomic<uint64_t>, 4> dropped{};
  std::array<uint64_t, 4> written{};
  uint64_t num_flushes = 0, num_chunks = 0;
  double last_flush_run_time = 0;  // flush_if_due(): the run time of the last flush
  std::vector<double> staging;     // rows_per_chunk x widest row, preallocated
  mutable std::mutex file_mutex;   // the flush thread against flush()/close(): never taken by append
  std::mutex wake_mutex;
  std::condition_variable wake;
  bool stop = false;
  std::thread thread;

  ~Impl() {
    if (file) std::fclose(file);  // only when the constructor failed after opening
  }

  void write_bytes(const void* p, size_t n) {
    if (std::fwrite(p, 1, n, file) != n) throw TraceError(path, "write failed");
  }

  void write_chunk(TraceChunk type, size_t num_cols, const double* rows, uint64_t num_rows) {
    const uint32_t head[2] = {static_cast<uint32_t>(type), static_cast<uint32_t>(num_cols)};
    write_bytes(head, sizeof head);
    write_bytes(&num_rows, sizeof num_rows);
    write_bytes(rows, num_rows * num_cols * sizeof(double));
    ++num_chunks;
  }

  // Drains every ring into chunks and flushes the C stream. Caller holds file_mutex.
  void flush_locked() {
    if (!file) return;
    const TraceChunk types[4] = {TraceChunk::kTicks, TraceChunk::kSteps, TraceChunk::kContacts, TraceChunk::kEvents};
    for (int s = 0; s < 4; ++s) {
      RowRing& ring = *rings[s];
      const size_t w = ring.num_cols();
      for (;;) {
        size_t n = 0;
        while (n < settings.rows_per_chunk && ring.pop(&staging[n * w])) ++n;
        if (n == 0) break;
        write_chunk(types[s], w, staging.data(), n);
        written[s] += n;
        if (n < settings.rows_per_chunk) break;
      }
    }
    if (std::fflush(file) != 0) throw TraceError(path, "flush failed");
    ++num_flushes;
  }

  void run() {
    std::unique_lock<std::mutex> lock(wake_mutex);
    while (!stop) {
      wake.wait_for(lock, std::chrono::duration<double>(settings.flush_period), [this] { return stop; });
      lock.unlock();
      {
        std::lock_guard<std::mutex> g(file_mutex);
        try {
          flush_locked();
        } catch (const TraceError&) {
          // A failing disk: keep the loops running; close() reports it by throwing again.
        }
      }
      lock.lock();
    }
  }
};

TraceWriter::TraceWriter(const std::string& path, const TraceMeta& meta, const TraceWriterSettings& settings)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  m.settings = settings;
  if (!(settings.flush_period > 0 && settings.flush_period <= 1.0))
    throw TraceError(path, "flush_period must be in (0, 1] s, got " + std::to_string(settings.flush_period));
  if (settings.rows_per_chunk == 0) throw TraceError(path, "rows_per_chunk must be > 0");

  // Metadata first, so that a bad extra_json fails before the file exists.
  nlohmann::json j;
  j["format"] = "gauss6-trace";
  j["version"] = kTraceVersion;
  j["created"] = utc_now_iso8601();
  j["scene"] = meta.scene;
  j["device"] = {{"name", meta.device}, {"rate_hz", meta.device_rate_hz}, {"renders_force", meta.renders_force}};
  j["machine"] = machine_json();
  j["phases"] = nlohmann::json::array();
  for (const TracePhase& p : meta.phases) j["phases"].push_back({{"name", p.name}, {"start", p.start}});
  j["columns"] = columns_json();
  nlohmann::json codes;
  for (uint32_t c = 1; c <= 6; ++c) codes[std::to_string(c)] = to_string(static_cast<TraceEventCode>(c));
  j["event_codes"] = codes;
  try {
    j["extra"] = nlohmann::json::parse(meta.extra_json.empty() ? "{}" : meta.extra_json);
  } catch (const nlohmann::json::exception& e) {  // parse_error, or out_of_range for a number beyond a double
    throw TraceError(path, std::string("TraceMeta::extra_json is not JSON: ") + e.what());
  }
  const std::string meta_text = j.dump();

  m.rings[0] = std::make_unique<RowRing>(settings.tick_capacity, kTickCols);
  m.rings[1] = std::make_unique<RowRing>(settings.step_capacity, kStepCols);
  m.rings[2] = std::make_unique<RowRing>(settings.contact_capacity, kContactCols);
  m.rings[3] = std::make_unique<RowRing>(settings.event_capacity, kEventCols);
  m.staging.assign(settings.rows_per_chunk * kTickCols, 0.0);

  m.file = std::fopen(path.c_str(), "wb");
  if (!m.file) throw TraceError(path, std::string("cannot create the file: ") + std::strerror(errno));
  // Header: magic, version, flags (0), metadata length, metadata.
  const uint32_t version_flags[2] = {kTraceVersion, 0};
  const uint64_t meta_len = meta_text.size();
  m.write_bytes(kTraceMagic, sizeof kTraceMagic);
  m.write_bytes(version_flags, sizeof version_flags);
  m.write_bytes(&meta_len, sizeof meta_len);
  m.write_bytes(meta_text.data(), meta_text.size());
  if (std::fflush(m.file) != 0) throw TraceError(path, "flush failed");

  if (settings.background_thread) m.thread = std::thread([this] { impl_->run(); });
}

TraceWriter::~TraceWriter() {
  try {
    close();
  } catch (const TraceError&) {
    // A destructor must not throw; call close() to see the error.
  }
}

namespace {
template <size_t N>
bool push_row(RowRing& ring, std::atomic<uint64_t>& dropped, const std::array<double, N>& row) {
  if (ring.push(row.data())) return true;
  dropped.fetch_add(1, std::memory_order_relaxed);
  return false;
}
}  // namespace

bool TraceWriter::append(const TraceTick& r) noexcept {
  std::array<double, kTickCols> row;
  row[0] = r.t;
  put_pose(&row[1], r.X_WH);
  put_pose(&row[8], r.X_WS);
  for (int i = 0; i < 6; ++i) row[15 + i] = r.F[i];
  row[21] = r.num_contacts;
  row[22] = r.force_time;
  row[23] = static_cast<double>(static_cast<int>(r.status));
  row[24] = r.flags;
  row[25] = r.buttons;
  return push_row(*impl_->rings[0], impl_->dropped[0], row);
}

bool TraceWriter::append(const TraceStep& r) noexcept {
  const std::array<double, kStepCols> row = {static_cast<double>(r.step), r.t, r.update_time,
                                             static_cast<double>(r.num_contacts), static_cast<double>(r.status),
                                             r.update_cpu_time};
  return push_row(*impl_->rings[1], impl_->dropped[1], row);
}

bool TraceWriter::append(const TraceContact& r) noexcept {
  const std::array<double, kContactCols> row = {
      static_cast<double>(r.step), r.t, r.point_W.x(), r.point_W.y(), r.point_W.z(),
      r.normal_W.x(), r.normal_W.y(), r.normal_W.z(), r.separation};
  return push_row(*impl_->rings[2], impl_->dropped[2], row);
}

bool TraceWriter::append(const TraceEvent& r) noexcept {
  const std::array<double, kEventCols> row = {r.t, static_cast<double>(static_cast<uint32_t>(r.code)), r.value};
  return push_row(*impl_->rings[3], impl_->dropped[3], row);
}

void TraceWriter::flush() {
  std::lock_guard<std::mutex> g(impl_->file_mutex);
  impl_->flush_locked();
}

bool TraceWriter::flush_if_due(double run_time) {
  Impl& m = *impl_;
  if (!(run_time - m.last_flush_run_time >= m.settings.flush_period)) return false;
  m.last_flush_run_time = run_time;
  std::lock_guard<std::mutex> g(m.file_mutex);
  try {
    m.flush_locked();
  } catch (const TraceError&) {
    // A failing disk: the run goes on; close() reports it by throwing again.
  }
  return true;
}

void TraceWriter::close() {
  Impl& m = *impl_;
  if (m.thread.joinable()) {
    {
      std::lock_guard<std::mutex> g(m.wake_mutex);
      m.stop = true;
    }
    m.wake.notify_all();
    m.thread.join();
  }
  std::lock_guard<std::mutex> g(m.file_mutex);
  if (!m.file) return;
  std::FILE* f = m.file;
  try {
    m.flush_locked();
    std::array<double, kEndCols> end;
    for (int s = 0; s < 4; ++s) end[s] = static_cast<double>(m.dropped[s].load());
    m.write_chunk(TraceChunk::kEnd, kEndCols, end.data(), 1);
  } catch (const TraceError&) {
    std::fclose(f);
    m.file = nullptr;
    throw;
  }
  m.file = nullptr;
  if (std::fclose(f) != 0) throw TraceError(m.path, "close failed");
}

TraceWriterStats TraceWriter::stats() const {
  std::lock_guard<std::mutex> g(impl_->file_mutex);
  TraceWriterStats s;
  for (int i = 0; i < 4; ++i) {
    s.written[i] = impl_->written[i];
    s.dropped[i] = impl_->dropped[i].load();
  }
  s.num_flushes = impl_->num_flushes;
  s.num_chunks = impl_->num_chunks;
  return s;
}

const std::string& TraceWriter::path() const { return impl_->path; }

// ---------------------------------------------------------------------------
// Reader

Trace read_trace(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw TraceError(path, "cannot open the file");
  std::string bytes;
  try {
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  } catch (const std::bad_alloc&) {
    throw TraceError(path, "out of memory reading the file");
  }
  const size_t size = bytes.size();
  auto fail = [&](const std::string& problem) { return TraceError(path, problem); };

  // Header: magic (8), version (4), flags (4), metadata length (8), metadata.
  constexpr size_t kHeader = 24;
  if (size < kHeader) throw fail("not a gauss6 trace: " + std::to_string(size) + " bytes, shorter than the header");
  if (std::memcmp(bytes.data(), kTraceMagic, 8) != 0) throw fail("not a gauss6 trace: bad magic (expected \"G6TRACE\\0\")");
  Trace trace;
  uint32_t flags = 0;
  uint64_t meta_len = 0;
  std::memcpy(&trace.version, bytes.data() + 8, 4);
  std::memcpy(&flags, bytes.data() + 12, 4);
  std::memcpy(&meta_len, bytes.data() + 16, 8);
  if (trace.version < kTraceOldestVersion || trace.version > kTraceVersion)
    throw fail("unsupported trace version " + std::to_string(trace.version) + " (this reader reads versions " +
               std::to_string(kTraceOldestVersion) + " to " + std::to_string(kTraceVersion) + ")");
  if (meta_len > size - kHeader)
    throw fail("metadata block of " + std::to_string(meta_len) + " bytes runs past the end of the file");
  trace.meta_json = bytes.substr(kHeader, meta_len);
  if (!nlohmann::json::accept(trace.meta_json)) throw fail("the metadata block is not valid JSON");
  if (const size_t first = trace.meta_json.find_first_not_of(" \t\r\n");
      first == std::string::npos || trace.meta_json[first] != '{')
    throw fail("the metadata block is not a JSON object");

  trace.ticks.num_cols = kTickCols;
  trace.steps.num_cols = kStepCols;
  trace.contacts.num_cols = kContactCols;
  trace.events.num_cols = kEventCols;

  // Chunks: type (4), row width (4), row count (8), rows.
  size_t pos = kHeader + meta_len;
  while (pos < size) {
    if (size - pos < 16) {
      trace.warnings.push_back(path + ": cut mid-chunk at byte " + std::to_string(pos) +
                               " (partial chunk header); read up to the last complete chunk");
      break;
    }
    uint32_t type = 0, num_cols = 0;
    uint64_t num_rows = 0;
    std::memcpy(&type, bytes.data() + pos, 4);
    std::memcpy(&num_cols, bytes.data() + pos + 4, 4);
    std::memcpy(&num_rows, bytes.data() + pos + 8, 8);
    const size_t expected = expected_cols(type, trace.version);
    if (expected != 0 && num_cols != expected)
      throw fail("chunk at byte " + std::to_string(pos) + " of type " + std::to_string(type) + " has rows of " +
                 std::to_string(num_cols) + " values, expected " + std::to_string(expected));
    if (num_cols == 0) throw fail("chunk at byte " + std::to_string(pos) + " has rows of 0 values");
    const size_t remaining = size - pos - 16;
    if (num_rows > remaining / (8 * static_cast<uint64_t>(num_cols))) {
      trace.warnings.push_back(path + ": cut mid-chunk at byte " + std::to_string(pos) + " (" +
                               std::to_string(num_rows) + " rows announced, " + std::to_string(remaining) +
                               " bytes left); read up to the last complete chunk");
      break;
    }
    const size_t n = static_cast<size_t>(num_rows) * num_cols;
    const char* payload = bytes.data() + pos + 16;
    TraceTable* table = nullptr;
    switch (static_cast<TraceChunk>(type)) {
      case TraceChunk::kTicks: table = &trace.ticks; break;
      case TraceChunk::kSteps: table = &trace.steps; break;
      case TraceChunk::kContacts: table = &trace.contacts; break;
      case TraceChunk::kEvents: table = &trace.events; break;
      case TraceChunk::kEnd:
        if (num_rows >= 1) {
          for (int s = 0; s < 4; ++s) {
            double d;
            std::memcpy(&d, payload + 8 * s, 8);
            if (!integer_in(d, 0, kMaxCount))
              throw fail("end chunk at byte " + std::to_string(pos) + ": dropped count " + std::to_string(d) +
                         " is not an integer in [0, 2^53]");
            trace.dropped[s] = static_cast<uint64_t>(d);
          }
        }
        trace.complete = true;
        break;
      default:
        trace.warnings.push_back(path + ": skipped a chunk of unknown type " + std::to_string(type) + " at byte " +
                                 std::to_string(pos));
    }
    if (table == &trace.steps && num_cols == kStepColsV1 && n > 0) {
      // Version 1 steps: widened to the current row, update_cpu_time NaN (not measured).
      const size_t old = table->data.size();
      table->data.resize(old + static_cast<size_t>(num_rows) * kStepCols);  // bounded as below
      for (size_t i = 0; i < static_cast<size_t>(num_rows); ++i) {
        double* row = table->data.data() + old + i * kStepCols;
        std::memcpy(row, payload + i * kStepColsV1 * 8, kStepColsV1 * 8);
        row[kStepColsV1] = std::numeric_limits<double>::quiet_NaN();
      }
    } else if (table && n > 0) {  // memcpy from an empty vector's null data() is undefined
      const size_t old = table->data.size();
      table->data.resize(old + n);  // n * 8 <= the file's size: bounded above
      std::memcpy(table->data.data() + old, payload, n * 8);
    }
    pos += 16 + n * 8;
  }
  if (const std::string problem = check_integer_columns(trace); !problem.empty()) throw fail(problem);
  if (!trace.complete && trace.warnings.empty())
    trace.warnings.push_back(path + ": no end chunk: the writer did not close the file (a crash loses the last flush period)");
  return trace;
}

TraceTick trace_tick(const Trace& trace, size_t i) {
  const double* r = trace.ticks.row(i);
  TraceTick t;
  t.t = r[0];
  t.X_WH = get_pose(r + 1);
  t.X_WS = get_pose(r + 8);
  for (int k = 0; k < 6; ++k) t.F[k] = r[15 + k];
  t.num_contacts = static_cast<int>(r[21]);
  t.force_time = r[22];
  t.status = static_cast<DeviceStatus>(static_cast<int>(r[23]));
  t.flags = static_cast<uint32_t>(r[24]);
  t.buttons = static_cast<uint32_t>(r[25]);
  return t;
}

}  // namespace gauss6
