// The proxy geometry of a volume, drawn with a mesh shader (VK_EXT_mesh_shader): one workgroup per volume emits the 12
// triangles of its bounding box, front faces outward, so that the fragment stage marches only the pixels the volume
// covers. Compiled and validated in CI (tests/CMakeLists.txt); not run on machines without mesh shaders.
#version 460
#extension GL_EXT_mesh_shader : require

layout(local_size_x = 1) in;
layout(triangles, max_vertices = 8, max_primitives = 12) out;

struct VolumeProxy {
    mat4 worldFromBox;  // the unit box [0, 1]^3 to world space
};

layout(std430, set = 0, binding = 0) readonly buffer Volumes { VolumeProxy volumes[]; };
layout(std140, set = 0, binding = 1) uniform Camera {
    mat4 clipFromWorld;
} camera;

layout(location = 0) out vec3 boxPosition[];                     // per vertex: position in [0, 1]^3
layout(location = 1) perprimitiveEXT flat out uint volumeIndex[];  // per triangle: which volume

// Corner c of the unit box has coordinates (c & 1, (c >> 1) & 1, (c >> 2) & 1).
const uvec3 kTriangles[12] = uvec3[](
    uvec3(0, 2, 1), uvec3(1, 2, 3),   // z = 0
    uvec3(4, 5, 6), uvec3(5, 7, 6),   // z = 1
    uvec3(0, 1, 4), uvec3(1, 5, 4),   // y = 0
    uvec3(2, 6, 3), uvec3(3, 6, 7),   // y = 1
    uvec3(0, 4, 2), uvec3(2, 4, 6),   // x = 0
    uvec3(1, 3, 5), uvec3(3, 7, 5));  // x = 1

void main() {
    uint volume = gl_WorkGroupID.x;
    mat4 clipFromBox = camera.clipFromWorld * volumes[volume].worldFromBox;

    SetMeshOutputsEXT(8, 12);
    for (uint c = 0; c < 8; ++c) {
        vec3 corner = vec3(c & 1u, (c >> 1) & 1u, (c >> 2) & 1u);
        gl_MeshVerticesEXT[c].gl_Position = clipFromBox * vec4(corner, 1.0f);
        boxPosition[c] = corner;
    }
    for (uint t = 0; t < 12; ++t) {
        gl_PrimitiveTriangleIndicesEXT[t] = kTriangles[t];
        volumeIndex[t] = volume;
    }
}
