// The budget of one god-object update (step 4 of the sim step: its CCDs and
// the contact set at the pose it ends at): CPU time, or a deterministic count
// of the work done, or both. When it runs out, the update ends with what is
// already proven (docs/sim-step.md, "Budgeted updates"): the god-object at the
// end of the longest motion its CCDs proved free, the contact set exact there;
// the next update goes on from that pose.
//
// Work units: the CCD charges each piece of work it does as it does it, with
// the weights below (kWorkWeight*), calibrated so that one unit is about
// kInstructionsPerUnit instructions of the optimized build on the recorded
// scenarios (docs/benchmarks.md, "Budgeted updates"). A count depends only on
// the inputs and the code, never on the machine: a lockstep run with a
// work-unit budget repeats bit for bit anywhere. The CPU form reads the
// thread's CPU clock (CLOCK_THREAD_CPUTIME_ID: a system call), so only every
// check_interval units; between two reads the update runs on by at most that
// many units and one indivisible piece of work (a triangle pair's narrow-phase
// test), the overrun the benchmarks measure.
//
// Real time: no allocation, no locks, no exceptions.
#pragma once

namespace gauss6 {

// The pieces of work the CCD charges, and their weights in work units
// (instructions per piece, divided by kInstructionsPerUnit and rounded;
// docs/benchmarks.md gives the fit).
enum class Work { kNodePair = 0, kTrianglePair, kPairTest, kFeatureBound, kFeatureQuery, kBox };
inline constexpr int kNumWorkKinds = 6;
inline constexpr long kWorkWeight[kNumWorkKinds] = {
    1,   // kNodePair: a node pair of a tree descent or fill (boxes tested)
    2,   // kTrianglePair: a candidate triangle pair's time or gap bound
    4,   // kPairTest: a narrow-phase test's set-up (a triangle pair: its swept and posed corners)
    2,   // kFeatureBound: a feature pair's own time bound (past its box filter)
    16,  // kFeatureQuery: a rigid narrow-phase query (its u-filter; boxes apart), a feature pair past its bound
    2,   // kBox: a narrow-phase box (one bisection of a feature pair)
};
inline constexpr long kInstructionsPerUnit = 730;    // about, per unit (the calibration's ratio)
// The work units of `count` pieces of one kind (every count of units is made here).
inline constexpr long work_units(Work kind, long count) { return kWorkWeight[static_cast<int>(kind)] * count; }

// CPU time that a 1 kHz sim loop can give a god-object update on every update:
// the period (1 ms) less the rest of the sim step (the projection, publishing:
// tens of microseconds), less the overrun of a budgeted update measured on
// this machine (kUpdateOverrunBound), less a margin for a slower machine:
// 0.4 + 0.25 ms at most, 1.5 times that within the period.
inline constexpr double kRecommendedUpdateCpuSeconds = 0.4e-3;
// The most a budgeted update's CPU time may exceed its CPU budget (s): the
// work between two reads of the clock (check_interval units), the largest
// indivisible piece (a triangle pair's narrow-phase test), and the contact set
// at the pose the update ends at; measured on this machine by the budgeted
// replays (docs/benchmarks.md), which count the steps beyond it.
inline constexpr double kUpdateOverrunBound = 0.25e-3;
// Work units between two reads of the CPU clock (a read costs about a
// microsecond on a VM; 64 units, about 47,000 instructions, 10-20 us here).
inline constexpr long kDefaultBudgetCheckInterval = 64;

struct UpdateBudgetSettings {
  double cpu_seconds = 0;   // CPU time per update (s, > 0; 0: no time budget; kRecommendedUpdateCpuSeconds)
  long work_units = 0;      // work units per update (> 0; 0: no count budget); deterministic
  long check_interval = kDefaultBudgetCheckInterval;  // units between reads of the CPU clock (>= 1)
  bool active() const { return cpu_seconds > 0 || work_units > 0; }
};

// Why the settings cannot serve (nullptr when they can): cpu_seconds and
// work_units finite and >= 0, check_interval >= 1.
const char* update_budget_settings_problem(const UpdateBudgetSettings& settings);

// One update's budget: started at the update's start, charged by the CCD.
class UpdateBudget {
 public:
  // A new update under `settings` (reads the CPU clock once when it has a time budget).
  void start(const UpdateBudgetSettings& settings) noexcept;
  // Charges `count` pieces of work of one kind; true when the budget has run out (by now or before).
  bool spend(Work kind, long count) noexcept {
    pieces_[static_cast<int>(kind)] += count;
    used_ += work_units(kind, count);
    if (used_ >= next_check_) check();
    return exhausted_;
  }
  long pieces(Work kind) const { return pieces_[static_cast<int>(kind)]; }  // charged in this update
  bool exhausted() const { return exhausted_; }
  long used() const { return used_; }       // units charged in this update
  double cpu_start() const { return cpu_start_; }  // s, thread CPU clock at start() (time budget only)

 private:
  void check() noexcept;
  UpdateBudgetSettings settings_;
  long used_ = 0;
  long pieces_[kNumWorkKinds] = {};
  long next_check_ = 0;      // the count at which the budget is checked next
  double cpu_start_ = 0;
  bool exhausted_ = false;
};

}  // namespace gauss6
