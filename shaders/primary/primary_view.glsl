// What both stages of the primary-hits raster pass share (renderers/framework/src/primary_hits.cpp): the BVH's
// triangles (binding 1; binding 0 holds its nodes, unused here) and the camera with the grid's samples per side.

#define TY_BVH_NODES_BINDING 0
#define TY_BVH_TRIANGLES_BINDING 1
#include "../include/bvh_buffers.glsl"
#include "../shared/camera.h"
#include "../shared/primary_hits.h"

layout(push_constant) uniform Push {
    CameraParams camera;  // of the image, not of the grid
    int samplesPerSide;   // S
} push;
