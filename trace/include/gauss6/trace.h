// Run traces: what every gauss6 run records, per haptic tick and per sim step,
// in the versioned binary format of docs/trace-format.md (magic "G6TRACE\0").
//
// Writing: TraceWriter takes rows from the real-time loops into fixed-capacity
// lock-free rings allocated when it opens (append_*: no allocation, no lock, no
// exception; a full ring drops the row and counts it). A background thread (or
// the caller, through flush()) drains the rings into self-delimiting chunks and
// flushes the file at least every flush_period seconds, so a crash loses at most
// that much. Reading: read_trace() returns every complete chunk; a file cut
// mid-chunk reads up to its last complete chunk with a warning; a malformed file
// throws TraceError naming the file and the problem. A Python reader with the
// same behaviour is python/gauss6/trace.py.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "gauss6/runtime/device_port.h"
#include "gauss6/io/load_error.h"
#include "gauss6/geometry/pose.h"

namespace gauss6 {

// Version 2 added the steps' update_cpu_time column; readers read versions 1 and 2
// (a version 1 step reads with update_cpu_time NaN: not measured).
inline constexpr uint32_t kTraceVersion = 2;
inline constexpr uint32_t kTraceOldestVersion = 1;
inline constexpr char kTraceMagic[8] = {'G', '6', 'T', 'R', 'A', 'C', 'E', '\0'};

// Chunk types (docs/trace-format.md). Readers skip types they do not know.
enum class TraceChunk : uint32_t { kTicks = 1, kSteps = 2, kContacts = 3, kEvents = 4, kEnd = 5 };

// Row widths in float64 values, fixed by the version (2; version 1: kStepColsV1).
inline constexpr size_t kTickCols = 26;     // t, xh (p 3, q 4), xs (p 3, q 4), F (6), contacts, force time, status, flags, buttons
inline constexpr size_t kStepCols = 6;      // step, t, update time, contacts, status, update CPU time
inline constexpr size_t kStepColsV1 = 5;    // version 1: without the update CPU time
inline constexpr size_t kContactCols = 9;   // step, t, point (3), normal (3), separation
inline constexpr size_t kEventCols = 3;     // t, code, value
inline constexpr size_t kEndCols = 4;       // rows dropped: ticks, steps, contacts, events

// Bits of TraceTick::flags.
enum TraceTickFlag : uint32_t {
  kTickGripped = 1u << 0,         // the user holds the handle (DeviceState::gripped)
  kTickNewContactSet = 1u << 1,   // a new contact set arrived from the sim loop this tick
  kTickForceClamped = 1u << 2,    // the wrench was clamped to the device's limits
  kTickWatchdog = 1u << 3,        // the watchdog zeroed the force this tick
};

// Event codes; codes >= 1000 are free for other engines (name them in the metadata).
enum class TraceEventCode : uint32_t {
  kPhase = 1,               // value: index of the phase in the metadata's phases
  kLetGo = 2,               // the user let go of the handle
  kWatchdog = 3,            // value: the late loop's period (s)
  kDeviceLost = 4,          // the device stopped answering (unplugged)
  kDeviceReconnected = 5,
  kDeviceEnded = 6,         // a script or a replay reached its end
};
const char* to_string(TraceEventCode c);

// One haptic tick. Frames: world; F = (force, torque about the handle's point).
struct TraceTick {
  double t = 0;                 // s since the run started
  Pose X_WH;                    // xh: the handle
  Pose X_WS;                    // xs: the god-object as the coupling loop last saw it
  Vec6 F = Vec6::Zero();        // wrench sent (or recorded, for input-only devices)
  int num_contacts = 0;         // rows of J used for this tick's force
  double force_time = 0;        // s spent computing the force this tick
  DeviceStatus status = DeviceStatus::kOk;
  uint32_t flags = 0;           // TraceTickFlag bits
  uint32_t buttons = 0;
};

// One god-object (sim) step; its contacts follow as TraceContact rows with the same step index.
struct TraceStep {
  uint64_t step = 0;            // 0, 1, 2, ... in the run
  double t = 0;                 // s since the run started, when the step finished
  double update_time = 0;       // s spent in the step (wall clock)
  int num_contacts = 0;
  int status = 0;               // the sim step's status code (0: ok)
  double update_cpu_time = 0;   // s of the sim thread's CPU time in the step (NaN: not measured, version 1)
};

struct TraceContact {
  uint64_t step = 0;
  double t = 0;
  Vec3 point_W = Vec3::Zero();   // contact point I_k, world frame
  Vec3 normal_W = Vec3::Zero();  // unit normal n_k, out of the obstacle
  double separation = 0;         // scene units, >= 0 when kept apart
};

struct TraceEvent {
  double t = 0;
  TraceEventCode code = TraceEventCode::kPhase;
  double value = 0;
};

struct TracePhase {
  std::string name;
  double start = 0;  // s
};

// Run metadata, stored as the JSON block of the header. The writer adds the
// format name, the version, the column names, the event codes, the creation
// time and the machine (host, CPU, cores, compiler).
struct TraceMeta {
  std::string scene;                // scene name or file
  std::string device;               // DeviceInfo::name
  double device_rate_hz = 0;
  bool renders_force = true;
  std::vector<TracePhase> phases;
  std::string extra_json = "{}";    // a JSON object merged under "extra"
};

// A trace file that cannot be read, written or made: "FILE: problem". One of the
// load-time errors (load_error.h), so a caller catches every file's error alike.
class TraceError : public LoadError {
 public:
  TraceError(std::string file, std::string problem) : LoadError(std::move(file), std::move(problem)) {}
};

struct TraceWriterSettings {
  double flush_period = 0.25;           // s between flushes (<= 1 s): of wall time by the background
                                        // thread, of run time by flush_if_due()
  size_t tick_capacity = 1u << 15;      // rows per ring, rounded up to a power of two
  size_t step_capacity = 1u << 12;
  size_t contact_capacity = 1u << 16;
  size_t event_capacity = 1u << 10;
  size_t rows_per_chunk = 4096;         // at most this many rows per chunk
  bool background_thread = true;        // false: the caller calls flush() (lockstep runs)
};

struct TraceWriterStats {
  std::array<uint64_t, 4> written{};    // rows written: ticks, steps, contacts, events
  std::array<uint64_t, 4> dropped{};    // rows dropped because a ring was full
  uint64_t num_flushes = 0;
  uint64_t num_chunks = 0;
};

class TraceWriter {
 public:
  // Creates the file and writes the header. Throws TraceError (load time).
  TraceWriter(const std::string& path, const TraceMeta& meta, const TraceWriterSettings& settings = {});
  ~TraceWriter();  // close()
  TraceWriter(const TraceWriter&) = delete;
  TraceWriter& operator=(const TraceWriter&) = delete;

  // Real-time: copy one row into its ring. False (and counted) when the ring is full.
  // Any thread may call them (the rings are multi-producer).
  bool append(const TraceTick& row) noexcept;
  bool append(const TraceStep& row) noexcept;
  bool append(const TraceContact& row) noexcept;
  bool append(const TraceEvent& row) noexcept;

  // Non-real-time: write what the rings hold as chunks and flush the file.
  void flush();
  // Flushes when flush_period s of run time have passed since the last call that
  // flushed: the bound a crash may lose, in run time, for runs faster than the wall
  // clock (a lockstep run flushes from its loop's thread, 17-50x real time). Called by
  // one thread; not for real-time threads (it writes the file). True if it flushed.
  bool flush_if_due(double run_time);
  // Stops the thread, flushes, writes the end chunk (dropped counts) and closes. Idempotent.
  void close();

  TraceWriterStats stats() const;
  const std::string& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Rows of one stream: num_rows x num_cols float64, row-major.
struct TraceTable {
  size_t num_cols = 0;
  std::vector<double> data;
  size_t num_rows() const { return num_cols ? data.size() / num_cols : 0; }
  const double* row(size_t i) const { return data.data() + i * num_cols; }
};

struct Trace {
  uint32_t version = 0;
  std::string meta_json;                 // the header's JSON block, as written
  TraceTable ticks, steps, contacts, events;
  bool complete = false;                 // the end chunk was found: the writer closed cleanly
  std::array<uint64_t, 4> dropped{};     // from the end chunk (zero if incomplete)
  std::vector<std::string> warnings;     // e.g. "cut mid-chunk at byte 1234: ..."
};

// Reads a whole trace. Throws TraceError("<path>: <problem>") on a malformed file.
Trace read_trace(const std::string& path);

// Row i of trace.ticks as a TraceTick (i < trace.ticks.num_rows()).
TraceTick trace_tick(const Trace& trace, size_t i);

// The column names of each stream, grouped (name, width), as written in the metadata.
struct TraceColumn {
  const char* name;
  int width;
};
const std::vector<TraceColumn>& trace_columns(TraceChunk chunk);

}  // namespace gauss6
