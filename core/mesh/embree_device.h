// RAII handle on an Embree device, shareable by several BVH-based queries.
#pragma once

#include <embree3/rtcore.h>

#include <string>

namespace mq {

// Name of an Embree error code, e.g. "RTC_ERROR_OUT_OF_MEMORY".
const char* embree_error_name(RTCError error);

// Reference-counted handle on an RTCDevice: copies share the device (rtcRetainDevice), the
// last one releases it. Objects built on the device (scenes) keep a copy so the device
// outlives them. A moved-from handle is empty (get() == nullptr).
class EmbreeDevice {
 public:
  // Creates a device with the given Embree configuration string ("" for defaults).
  // Throws Error, naming the Embree error, if the device cannot be created.
  explicit EmbreeDevice(const std::string& config = "");
  ~EmbreeDevice();
  EmbreeDevice(const EmbreeDevice& other);
  EmbreeDevice& operator=(const EmbreeDevice& other);
  EmbreeDevice(EmbreeDevice&& other) noexcept;
  EmbreeDevice& operator=(EmbreeDevice&& other) noexcept;

  RTCDevice get() const { return device_; }

  // Throws Error("<what>: Embree error RTC_ERROR_...") if the device has a pending error
  // (which this call clears); does nothing otherwise.
  void check(const char* what) const;

 private:
  RTCDevice device_ = nullptr;
};

}  // namespace mq
