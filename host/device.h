// Choice of compute path shared by the evaluator factories.
#pragma once

namespace mq {

enum class Device {
  Cpu,     // TBB path
  OpenCL,  // kernel on the device chosen by RuntimeOptions / environment
  Auto,    // OpenCL when a platform with a double-precision device exists, else CPU
};

}  // namespace mq
