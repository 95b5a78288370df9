#include "reference/embree_scene.h"

#include "tyndall/core/error.h"

#include <cmath>
#include <limits>
#include <string>

namespace tyndall::reference {

namespace {

void throwOnEmbreeError(RTCDevice device, const char* what) {
    RTCError error = rtcGetDeviceError(device);
    if (error != RTC_ERROR_NONE)
        throw std::runtime_error(std::string("Embree failed to ") + what + " (error " + std::to_string(int(error)) + ")");
}

// The collector that rides along a volume query: Embree hands our context back to the user-geometry callbacks.
struct CollectContext {
    RTCIntersectContext context;  // must stay first
    const EmbreeScene* scene;
    std::vector<VolumeHit>* out;
};

void volumeBounds(const RTCBoundsFunctionArguments* args) {
    const auto* volumes = static_cast<const std::vector<ConvexVolume>*>(args->geometryUserPtr);
    const ConvexVolume& v = (*volumes)[args->primID];
    args->bounds_o->lower_x = v.boundsMin.x;
    args->bounds_o->lower_y = v.boundsMin.y;
    args->bounds_o->lower_z = v.boundsMin.z;
    args->bounds_o->upper_x = v.boundsMax.x;
    args->bounds_o->upper_y = v.boundsMax.y;
    args->bounds_o->upper_z = v.boundsMax.z;
}

// Records the clipped interval and reports no hit, so that traversal goes on to every overlapping volume.
void volumeCollect(const RTCOccludedFunctionNArguments* args) {
    auto* collect = reinterpret_cast<CollectContext*>(args->context);
    const auto* volumes = static_cast<const std::vector<ConvexVolume>*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        if (!args->valid[i]) continue;
        vec3 o(RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
               RTCRayN_org_z(args->ray, args->N, i));
        vec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
               RTCRayN_dir_z(args->ray, args->N, i));
        float t0 = RTCRayN_tnear(args->ray, args->N, i);
        float t1 = RTCRayN_tfar(args->ray, args->N, i);
        if (EmbreeScene::clip((*volumes)[args->primID], o, d, t0, t1))
            collect->out->push_back(VolumeHit{t0, t1, args->primID});
    }
}

void volumeIntersectUnused(const RTCIntersectFunctionNArguments*) {}

RTCRay makeRay(const vec3& origin, const vec3& dir, float tnear, float tfar) {
    RTCRay ray{};
    ray.org_x = origin.x;
    ray.org_y = origin.y;
    ray.org_z = origin.z;
    ray.dir_x = dir.x;
    ray.dir_y = dir.y;
    ray.dir_z = dir.z;
    ray.tnear = tnear;
    ray.tfar = tfar;
    ray.mask = 0xffffffffu;
    return ray;
}

}  // namespace

bool EmbreeScene::clip(const ConvexVolume& volume, const vec3& origin, const vec3& dir, float& t0, float& t1) {
    for (const vec4& plane : volume.planes) {
        vec3 n(plane);
        float denom = glm::dot(n, dir);
        float dist = plane.w - glm::dot(n, origin);  // >= 0 inside
        if (denom == 0.0f) {
            if (dist < 0.0f) return false;
            continue;
        }
        float t = dist / denom;
        if (denom > 0.0f) t1 = std::min(t1, t);
        else t0 = std::max(t0, t);
        if (t0 >= t1) return false;
    }
    return t0 < t1;
}

EmbreeScene::EmbreeScene(const std::vector<TriangleGeometry>& meshes, std::vector<ConvexVolume> volumes)
    : meshes_(meshes), volumes_(std::move(volumes)) {
    // No "threads=N" here: Embree applies it as a process-wide TBB limit, which would serialise the renders too.
    device_ = rtcNewDevice(nullptr);
    if (!device_) throw std::runtime_error("Embree could not create a device");

    surfaces_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(surfaces_, RTC_BUILD_QUALITY_HIGH);
    rtcSetSceneFlags(surfaces_, RTC_SCENE_FLAG_ROBUST);
    for (unsigned m = 0; m < meshes_.size(); ++m) {
        const TriangleGeometry& mesh = meshes_[m];
        RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* positions = static_cast<float*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(float) * 3, mesh.positions.size()));
        for (size_t i = 0; i < mesh.positions.size(); ++i) {
            positions[3 * i + 0] = mesh.positions[i].x;
            positions[3 * i + 1] = mesh.positions[i].y;
            positions[3 * i + 2] = mesh.positions[i].z;
        }
        auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, sizeof(unsigned) * 3, mesh.triangles.size()));
        for (size_t i = 0; i < mesh.triangles.size(); ++i) {
            indices[3 * i + 0] = mesh.triangles[i].x;
            indices[3 * i + 1] = mesh.triangles[i].y;
            indices[3 * i + 2] = mesh.triangles[i].z;
        }
        rtcCommitGeometry(geometry);
        rtcAttachGeometryByID(surfaces_, geometry, m);
        rtcReleaseGeometry(geometry);
    }
    rtcCommitScene(surfaces_);
    throwOnEmbreeError(device_, "build the surface BVH");

    volumeScene_ = rtcNewScene(device_);
    if (!volumes_.empty()) {
        RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(volumes_.size()));
        rtcSetGeometryUserData(geometry, &volumes_);
        rtcSetGeometryBoundsFunction(geometry, volumeBounds, nullptr);
        rtcSetGeometryIntersectFunction(geometry, volumeIntersectUnused);
        rtcSetGeometryOccludedFunction(geometry, volumeCollect);
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(volumeScene_, geometry);
        rtcReleaseGeometry(geometry);
    }
    rtcCommitScene(volumeScene_);
    throwOnEmbreeError(device_, "build the volume BVH");
}

EmbreeScene::~EmbreeScene() {
    if (volumeScene_) rtcReleaseScene(volumeScene_);
    if (surfaces_) rtcReleaseScene(surfaces_);
    if (device_) rtcReleaseDevice(device_);
}

bool EmbreeScene::intersect(const vec3& origin, const vec3& dir, float tnear, float tfar, SurfaceHit& hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh{};
    rh.ray = makeRay(origin, dir, tnear, tfar);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(surfaces_, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit.t = rh.ray.tfar;
    hit.mesh = rh.hit.geomID;
    hit.triangle = rh.hit.primID;
    hit.u = rh.hit.u;
    hit.v = rh.hit.v;
    hit.geometricNormal = glm::normalize(vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
    return true;
}

bool EmbreeScene::occluded(const vec3& origin, const vec3& dir, float tnear, float tfar) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray = makeRay(origin, dir, tnear, tfar);
    rtcOccluded1(surfaces_, &context, &ray);
    return ray.tfar < 0.0f;  // Embree sets tfar to -inf on occlusion
}

void EmbreeScene::volumeIntervals(const vec3& origin, const vec3& dir, float tnear, float tfar,
                                  std::vector<VolumeHit>& out) const {
    if (volumes_.empty()) return;
    CollectContext collect;
    rtcInitIntersectContext(&collect.context);
    collect.scene = this;
    collect.out = &out;
    RTCRay ray = makeRay(origin, dir, tnear, std::min(tfar, std::numeric_limits<float>::max()));
    rtcOccluded1(volumeScene_, &collect.context, &ray);
}

}  // namespace tyndall::reference
