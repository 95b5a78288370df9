#include "tyndall/framework/device.h"

#include "tyndall/gpu/context.h"

namespace tyndall {

ParamInfo deviceParameter(std::string doc) {
    return {"device", ParamType::Enum, std::move(doc), "", 0, 0, std::string("auto"), {"auto", "gpu", "cpu"}};
}

Device deviceFrom(const ParamSet& params) {
    const std::string& device = params.getEnum("device");
    return device == "gpu" ? Device::Gpu : device == "cpu" ? Device::Cpu : Device::Auto;
}

bool runsOnGpu(Device device, AutoDevice rule) {
    if (device != Device::Auto) return device == Device::Gpu;
    switch (rule) {
        case AutoDevice::HardwareGpu:
            return gpu::hardwareDeviceAvailable();
        case AutoDevice::AnyGpu:
            try {
                return gpu::sharedContext() != nullptr;
            } catch (const gpu::GpuError&) {
                return false;
            }
        case AutoDevice::Gpu:
            return true;
    }
    return false;
}

}  // namespace tyndall
