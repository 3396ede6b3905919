// The names of the runtime's event kinds (runtime_events.h).
#include "gauss6/runtime/runtime_events.h"

namespace gauss6 {

const char* to_string(RuntimeEventKind k) {
  switch (k) {
    case RuntimeEventKind::kInvalidHandlePose: return "invalid_handle_pose";
    case RuntimeEventKind::kDeviceError: return "device_error";
    case RuntimeEventKind::kDeviceTimeout: return "device_timeout";
    case RuntimeEventKind::kSimStalled: return "sim_stalled";
    case RuntimeEventKind::kCouplingStalled: return "coupling_stalled";
    case RuntimeEventKind::kNonFiniteForce: return "non_finite_force";
    case RuntimeEventKind::kForceClamped: return "force_clamped";
    case RuntimeEventKind::kDeviceEnded: return "device_ended";
    case RuntimeEventKind::kProjectionFailed: return "projection_failed";
    case RuntimeEventKind::kCcdGaveUp: return "ccd_gave_up";
    case RuntimeEventKind::kContactOverflow: return "contact_overflow";
    case RuntimeEventKind::kTextureUndersampled: return "texture_undersampled";
    case RuntimeEventKind::kDeviceNotConnected: return "device_not_connected";
    case RuntimeEventKind::kDeviceWriteFailed: return "device_write_failed";
    case RuntimeEventKind::kHapticStalled: return "haptic_stalled";
    case RuntimeEventKind::kUpdateBudgetExhausted: return "update_budget_exhausted";
  }
  return "unknown";
}

}  // namespace gauss6
