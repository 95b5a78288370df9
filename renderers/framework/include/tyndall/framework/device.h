// Where a technique renders: its "device" parameter (auto, gpu or cpu) and what auto means for that technique. One
// definition for every technique that has a GPU and a CPU path, so that the parameter, its parsing and the lavapipe
// rule read the same everywhere.
#pragma once

#include "tyndall/core/params.h"

#include <string>

namespace tyndall {

enum class Device { Auto, Gpu, Cpu };

// What `auto` picks for a technique.
enum class AutoDevice {
    HardwareGpu,  // the GPU unless the only Vulkan device is a software one (lavapipe), where the CPU path is faster
    AnyGpu,       // any Vulkan device, lavapipe included; the CPU when there is none
    Gpu,          // the GPU (the technique checks the device's limits itself and may still fall back)
};

// The "device" parameter (enum auto, gpu, cpu; default auto) with `doc`, which says what auto does for the technique.
ParamInfo deviceParameter(std::string doc);
// The value of the "device" parameter.
Device deviceFrom(const ParamSet& params);
// Whether a render with `device` runs on the GPU: gpu and cpu as they say, auto by `rule`.
bool runsOnGpu(Device device, AutoDevice rule);

}  // namespace tyndall
