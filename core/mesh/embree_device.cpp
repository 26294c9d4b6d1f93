#include "core/mesh/embree_device.h"

#include <utility>

#include "core/common/errors.h"

namespace mq {

const char* embree_error_name(RTCError error) {
  switch (error) {
    case RTC_ERROR_NONE:
      return "RTC_ERROR_NONE";
    case RTC_ERROR_UNKNOWN:
      return "RTC_ERROR_UNKNOWN";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "RTC_ERROR_INVALID_ARGUMENT";
    case RTC_ERROR_INVALID_OPERATION:
      return "RTC_ERROR_INVALID_OPERATION";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "RTC_ERROR_OUT_OF_MEMORY";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "RTC_ERROR_UNSUPPORTED_CPU";
    case RTC_ERROR_CANCELLED:
      return "RTC_ERROR_CANCELLED";
  }
  return "unrecognised Embree error";
}

EmbreeDevice::EmbreeDevice(const std::string& config) {
  device_ = rtcNewDevice(config.empty() ? nullptr : config.c_str());
  // With a null device, rtcGetDeviceError reports the thread's device-creation error.
  if (!device_)
    MQ_THROW(Error, "cannot create Embree device: Embree error ",
             embree_error_name(rtcGetDeviceError(nullptr)));
}

EmbreeDevice::~EmbreeDevice() {
  if (device_) rtcReleaseDevice(device_);
}

EmbreeDevice::EmbreeDevice(const EmbreeDevice& other) : device_(other.device_) {
  if (device_) rtcRetainDevice(device_);
}

EmbreeDevice& EmbreeDevice::operator=(const EmbreeDevice& other) {
  if (this != &other) {
    if (other.device_) rtcRetainDevice(other.device_);
    if (device_) rtcReleaseDevice(device_);
    device_ = other.device_;
  }
  return *this;
}

EmbreeDevice::EmbreeDevice(EmbreeDevice&& other) noexcept
    : device_(std::exchange(other.device_, nullptr)) {}

EmbreeDevice& EmbreeDevice::operator=(EmbreeDevice&& other) noexcept {
  if (this != &other) {
    if (device_) rtcReleaseDevice(device_);
    device_ = std::exchange(other.device_, nullptr);
  }
  return *this;
}

void EmbreeDevice::check(const char* what) const {
  const RTCError error = rtcGetDeviceError(device_);
  if (error != RTC_ERROR_NONE) MQ_THROW(Error, what, ": Embree error ", embree_error_name(error));
}

}  // namespace mq
