// The LTSD technique's scene, prepared once per render for both paths: the std430 arrays of
// shaders/shared/ltsd_scene.h (frame with the phase function's fitted LTSDs, lights, medium planes, surfaces, the LTC
// GGX table when a material is GGX) and the BVH.
#pragma once

#include "tyndall/framework/gpu_surfaces.h"

#include "shared/ltsd_scene.h"
#include "tyndall/core/params.h"
#include "tyndall/core/scene.h"
#include "tyndall/framework/bound_scene.h"
#include "tyndall/framework/device.h"
#include "tyndall/tables/ltsd_table.h"

#include <string>
#include <vector>

namespace tyndall::ltsd {

struct Settings {
    Device device = Device::Auto;
    int nodes = 8;  // N of Eq. 15
    int placement = shader::kLtsdPlacementEquiangular;
    int transmittance = shader::kLtsdTransmittanceMinDistance;
    int supersampling = 1;
    int shadows = 2;         // 0 off, 1 the raw ratio estimators, 2 numerator and denominator denoised (kShadows*)
    int ratioSamples = 16;  // camera samples per pixel of the ratio estimators
    int sMethod = shader::kLtsdSMethodAccurate;
};

inline constexpr int kShadowsOff = 0;
inline constexpr int kShadowsRatio = 1;
inline constexpr int kShadowsRatioDenoised = 2;

Settings settingsFrom(const ParamSet& params);

// The names of the enum parameters, indexed by their shader constants.
const std::vector<std::string>& placementNames();
const std::vector<std::string>& transmittanceNames();
const std::vector<std::string>& shadowNames();
const std::vector<std::string>& sMethodNames();

struct PreparedScene {
    shader::LtsdFrame frame{};
    std::vector<shader::LtsdLight> lights;  // never empty (a dummy when the scene has none)
    std::vector<glm::vec4> planes;          // the medium's half-spaces (n, offset); never empty
    GpuSurfaces surfaces;
    bool anyTwoSided = false;
    double g = 0.0;         // the medium's HG (or mix) asymmetry (0 for the others)
    std::string tablePath;  // the LTSD table the frame's entries come from ("" without a medium, with the accurate S,
                            // or exact: isotropic, eddington)
    bool anyAnisotropic = false;               // an anisotropic GGX material (alphaX != alphaY)
    std::vector<shader::LtcEntry> ltcEntries;  // the LTC GGX tables' entries (isotropic, then anisotropic from
                                               // frame.ltcAnisoBase); a dummy without GGX
    std::string ltcTablePath;                  // the isotropic table ("" when no material needs it)
    std::string ltcAnisotropicTablePath;       // the anisotropic table ("" when no material needs it)
};

// The medium's phase function as the LTSD tables see it; throws InputError (with ltsdPhaseRefusal's reason) for one
// the technique cannot render.
LtsdPhase ltsdPhaseOf(const HomogeneousMedium& medium);

// Throws InputError for scene content the technique cannot render or that is inconsistent: more than one medium, too
// many lights, a table that is missing or corrupt.
PreparedScene prepareScene(const Scene& scene, const Settings& settings, const std::string& projectDir);

// Binds a prepared scene to the calling thread for the C++ definitions of the accessors of ltsd_scene.h (and its BVH
// for bvh.h's), so that the shared renderer runs on the CPU. The scene must outlive the scope.
class SceneScope : public BoundScene<PreparedScene>::Binding {
public:
    explicit SceneScope(const PreparedScene& scene) : Binding(scene, scene.surfaces.bvh) {}
};

}  // namespace tyndall::ltsd
