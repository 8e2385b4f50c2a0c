#pragma once
// How a glTF file becomes a scene to trace: which of its scenes, at which instant of its
// animations, with which camera and which face rule.
#include <string>

namespace dacrt {

// Which back faces no ray hits (a triangle's cull-back-face flag): the materials' (glTF's
// rule, the default), none, or every triangle's.
enum class CullMode { Material, None, BackFaces };

struct SceneLoadOptions {
    std::string scene;      // an index or a name of the file's scenes; empty: its default scene
    std::string animation;  // an index or a name; empty: every animation together
    double time = 0.0;      // seconds: the instant the animations, skins and morph targets are posed at
    std::string camera;     // a placed camera's name or index; empty: the first placed (if any)
    CullMode cull = CullMode::Material;
};

}  // namespace dacrt
