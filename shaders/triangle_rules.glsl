// Which triangles can be hit at all. Valid GLSL and, through host/core/triangle_rules.hpp,
// valid C++: the loader drops what this rejects, and every backend's intersection test
// applies it again, so that no path depends on the loader.
#ifndef DACRT_TRIANGLE_RULES_GLSL
#define DACRT_TRIANGLE_RULES_GLSL

// The degenerate-triangle rule of every backend and of the loader (pbrt-v4's): a triangle
// whose edges' cross product is zero in float32 has no area in the arithmetic the tests use,
// and is never hit. Written out (not GLSL's cross()) so that every device computes the same
// products in the same order.
bool triangleHasNoArea(vec3 p0, vec3 p1, vec3 p2) {
    precise vec3 e1 = p1 - p0;
    precise vec3 e2 = p2 - p0;
    precise float nx = e1.y * e2.z - e1.z * e2.y;
    precise float ny = e1.z * e2.x - e1.x * e2.z;
    precise float nz = e1.x * e2.y - e1.y * e2.x;
    return nx == 0.0 && ny == 0.0 && nz == 0.0;
}

// The face rule of every backend (glTF 2.0, "doubleSided": a single-sided material's back
// faces are culled). det is the intersection test's determinant, which every test here
// computes with the sign of -dot(d, (v1 - v0) x (v2 - v0)): positive when the ray meets the
// counter-clockwise (front) side. Zero never reaches this rule: such a triangle is edge-on.
bool backFaceIsCulled(bool cullBackFace, float det) {
    return cullBackFace && det < 0.0;
}

#endif
