// Names of the device statuses (device_port.h).
#include "gauss6/runtime/device_port.h"

namespace gauss6 {

const char* to_string(DeviceStatus s) {
  switch (s) {
    case DeviceStatus::kOk: return "ok";
    case DeviceStatus::kNotConnected: return "not_connected";
    case DeviceStatus::kTimeout: return "timeout";
    case DeviceStatus::kEnded: return "ended";
    case DeviceStatus::kError: return "error";
  }
  return "unknown";
}

}  // namespace gauss6
