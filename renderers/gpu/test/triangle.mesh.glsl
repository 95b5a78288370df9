#version 460
// The mesh-shader twin of triangles.vert.glsl: one workgroup emits triangle 0 of the list, with its flat colour.
#extension GL_EXT_mesh_shader : require
layout(local_size_x = 1) in;
layout(triangles, max_vertices = 3, max_primitives = 1) out;
layout(std430, set = 0, binding = 0) readonly buffer Triangles { vec4 triangles[]; };
layout(location = 0) flat out vec4 colour[];
void main() {
    vec4 ab = triangles[0], cd = triangles[1];
    SetMeshOutputsEXT(3, 1);
    gl_MeshVerticesEXT[0].gl_Position = vec4(ab.xy, 0.5, 1.0);
    gl_MeshVerticesEXT[1].gl_Position = vec4(ab.zw, 0.5, 1.0);
    gl_MeshVerticesEXT[2].gl_Position = vec4(cd.xy, 0.5, 1.0);
    for (int k = 0; k < 3; ++k) colour[k] = triangles[2];
    gl_PrimitiveTriangleIndicesEXT[0] = uvec3(0, 1, 2);
}
