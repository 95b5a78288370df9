// For test kernels that include shared/bvh.h: the BVH's two arrays as std430 structs at bindings 0 and 1 (the layout
// buildBvh uploads as is), and the accessors shared/bvh.h wants over them.
layout(std430, set = 0, binding = 0) readonly buffer BvhNodes { BvhNode bvhNodes[]; };
layout(std430, set = 0, binding = 1) readonly buffer BvhTriangles { BvhTriangle bvhTriangles[]; };
BvhNode bvhNode(int i) { return bvhNodes[i]; }
BvhTriangle bvhTriangle(int i) { return bvhTriangles[i]; }
