// The ISV passes' shared GLSL declarations: the view a proxy pass draws from (the camera, or a light's grid for the
// volumetric shadow map), std430.
#ifndef TY_ISV_VIEW_GLSL
#define TY_ISV_VIEW_GLSL

#include "../shared/camera.h"
#include "../shared/isv.h"

struct IsvView {
    CameraParams camera;
    float nearPlane;  // m: tetrahedra reaching closer are culled
    int width;        // pixels of the rendering resolution
    int height;
    int particleCount;
};

#endif  // TY_ISV_VIEW_GLSL
