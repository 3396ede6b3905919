// The hidapi backend of the HID driver (hid_device.h): hid_enumerate, hid_open_path,
// hid_read_timeout, hid_write, hid_close, with wide strings converted to UTF-8.
#include <hidapi/hidapi.h>

#include <cwchar>
#include <mutex>

#include "gauss6/hid_device.h"

namespace gauss6 {

namespace {

// UTF-8 of a wide string from hidapi (UTF-32 on Linux); empty for null.
std::string utf8(const wchar_t* w) {
  std::string out;
  if (!w) return out;
  for (; *w; ++w) {
    const uint32_t c = static_cast<uint32_t>(*w);
    if (c < 0x80) {
      out += static_cast<char>(c);
    } else if (c < 0x800) {
      out += static_cast<char>(0xc0 | (c >> 6));
      out += static_cast<char>(0x80 | (c & 0x3f));
    } else if (c < 0x10000) {
      out += static_cast<char>(0xe0 | (c >> 12));
      out += static_cast<char>(0x80 | ((c >> 6) & 0x3f));
      out += static_cast<char>(0x80 | (c & 0x3f));
    } else {
      out += static_cast<char>(0xf0 | (c >> 18));
      out += static_cast<char>(0x80 | ((c >> 12) & 0x3f));
      out += static_cast<char>(0x80 | ((c >> 6) & 0x3f));
      out += static_cast<char>(0x80 | (c & 0x3f));
    }
  }
  return out;
}

class HidapiBackend final : public HidBackend {
 public:
  HidapiBackend() { ok_ = hid_init() == 0; }
  ~HidapiBackend() override { hid_exit(); }

  std::vector<HidDeviceEntry> enumerate() override {
    std::vector<HidDeviceEntry> out;
    if (!ok_) return out;
    hid_device_info* list = hid_enumerate(0, 0);
    for (const hid_device_info* d = list; d; d = d->next) {
      HidDeviceEntry e;
      e.path = d->path ? d->path : "";
      e.vendor_id = d->vendor_id;
      e.product_id = d->product_id;
      e.serial = utf8(d->serial_number);
      e.manufacturer = utf8(d->manufacturer_string);
      e.product = utf8(d->product_string);
      e.interface_number = d->interface_number;
      out.push_back(std::move(e));
    }
    hid_free_enumeration(list);
    return out;
  }

  Handle open(const std::string& path) override {
    if (!ok_) return nullptr;
    return hid_open_path(path.c_str());
  }

  int read_timeout(Handle h, uint8_t* buf, size_t len, int timeout_ms) override {
    return hid_read_timeout(static_cast<hid_device*>(h), buf, len, timeout_ms);
  }

  int write(Handle h, const uint8_t* data, size_t len) override {
    return hid_write(static_cast<hid_device*>(h), data, len);
  }

  void close(Handle h) override {
    if (h) hid_close(static_cast<hid_device*>(h));
  }

 private:
  bool ok_ = false;
};

}  // namespace

std::shared_ptr<HidBackend> make_hidapi_backend() {
  // One backend per process: hid_init/hid_exit are process-wide.
  static std::mutex m;
  static std::weak_ptr<HidBackend> shared;
  std::lock_guard<std::mutex> g(m);
  if (auto b = shared.lock()) return b;
  auto b = std::make_shared<HidapiBackend>();
  shared = b;
  return b;
}

}  // namespace gauss6
