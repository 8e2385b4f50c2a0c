#pragma once
// glTF animations read, checked and sampled on the host: each channel's sampler (STEP, LINEAR
// with quaternion slerp, CUBICSPLINE) evaluated at one instant into the nodes' animated
// translation, rotation, scale and morph-target weights. Internal to the glTF loader.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/gltf_accessors.hpp"

namespace dacrt::gltf {

enum class Interpolation { Step, Linear, CubicSpline };
enum class AnimatedPath { Translation, Rotation, Scale, Weights };

struct AnimationSampler {
    std::vector<double> times;    // strictly increasing, finite
    std::vector<double> values;   // per key `width` numbers; CUBICSPLINE: in-tangent, value, out-tangent
    std::size_t width = 0;        // 3, 4 (a quaternion x, y, z, w) or the morph-target count
    Interpolation interpolation = Interpolation::Linear;
};

struct AnimationChannel {
    int node = -1;
    AnimatedPath path = AnimatedPath::Translation;
    std::size_t sampler = 0;
};

struct Animation {
    std::string name;
    std::vector<AnimationSampler> samplers;
    std::vector<AnimationChannel> channels;
    double start = 0.0;  // the earliest and latest key over its samplers
    double end = 0.0;
};

// The sampler's `width` numbers at time t (seconds), clamped to its first and last keys. A
// rotation (`quaternion`) is interpolated on the unit sphere (LINEAR: slerp along the shorter
// arc) and returned normalized.
std::vector<double> sampleAt(const AnimationSampler& sampler, double t, bool quaternion);

// Every animation of the model, checked: samplers' accessors in range and of the types the
// specification allows, keys strictly increasing, output counts that match, channels naming
// nodes that exist (without a matrix: glTF animates TRS only) and weights of meshes with as
// many morph targets. Channels of paths dacrt does not know are skipped with a warning.
std::vector<Animation> readAnimations(const AccessorReader& reader, std::vector<std::string>& warnings);

// Which animation `choice` names: an index or a name; empty: -1 (every animation). Fails
// through the reader, listing the animations, when it names none.
int chooseAnimation(const std::vector<Animation>& animations, const std::string& choice, const AccessorReader& reader);

// A node's animated properties at one instant; unset ones keep the node's own.
struct NodePose {
    std::optional<glm::dvec3> translation;
    std::optional<glm::dquat> rotation;
    std::optional<glm::dvec3> scale;
    std::optional<std::vector<double>> weights;
};

// The pose of every node at time t under one animation (its index) or all of them (-1; where
// two animate the same property of a node, the later in the file wins).
std::vector<NodePose> poseAt(const std::vector<Animation>& animations, int chosen, double t, std::size_t nodeCount);

}  // namespace dacrt::gltf
