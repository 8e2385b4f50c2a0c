#include "core/gltf_animation.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace dacrt::gltf {
namespace {

std::optional<int> indexChoice(const std::string& choice) {
    if (choice.empty() || choice.size() >= 10 || choice.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
    return std::stoi(choice);
}

// The key interval holding t: keys k and k + 1 with times[k] <= t < times[k + 1], and the
// fraction s of the way from one to the other. t at or past the last key: the last key, s = 0.
struct KeyInterval {
    std::size_t k = 0;
    double s = 0.0;
    double span = 0.0;
    bool last = false;
};

KeyInterval intervalOf(const std::vector<double>& times, double t) {
    if (times.size() == 1 || t <= times.front()) return {0, 0.0, 0.0, times.size() == 1};
    if (t >= times.back()) return {times.size() - 1, 0.0, 0.0, true};
    const std::size_t k = std::size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
    const double span = times[k + 1] - times[k];
    return {k, (t - times[k]) / span, span, false};
}

void normalizeQuaternion(std::vector<double>& q) {
    const double length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (length > 0.0 && std::isfinite(length))
        for (double& c : q) c /= length;
}

// Spherical linear interpolation along the shorter arc (glTF 2.0, appendix on interpolation);
// nearly parallel quaternions are lerped and normalized, where slerp's division loses accuracy.
std::vector<double> slerp(const double* a, const double* b, double s) {
    double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    const double sign = dot < 0.0 ? -1.0 : 1.0;
    dot *= sign;
    double wa, wb;
    if (dot > 0.9995) {
        wa = 1.0 - s;
        wb = s;
    } else {
        const double theta0 = std::acos(dot), theta = s * theta0;
        wb = std::sin(theta) / std::sin(theta0);
        wa = std::cos(theta) - dot * wb;
    }
    std::vector<double> q(4);
    for (int i = 0; i < 4; ++i) q[std::size_t(i)] = wa * a[i] + wb * sign * b[i];
    normalizeQuaternion(q);
    return q;
}

// How many morph targets the node's mesh has (every primitive of a mesh has as many); 0: none.
std::size_t morphTargetsOf(const tinygltf::Model& model, const tinygltf::Node& node) {
    if (node.mesh < 0 || std::size_t(node.mesh) >= model.meshes.size()) return 0;
    const tinygltf::Mesh& mesh = model.meshes[std::size_t(node.mesh)];
    return mesh.primitives.empty() ? 0 : mesh.primitives.front().targets.size();
}

// How the channels read each sampler: the path they animate and the numbers per key (none:
// no channel reads it).
using SamplerUses = std::vector<std::optional<std::pair<AnimatedPath, std::size_t>>>;

// The animation's channels, checked, and how they read its samplers (`use`). A sampler's width
// is known from the channels that use it, so channels come first.
std::vector<AnimationChannel> readChannels(const AccessorReader& reader, const tinygltf::Animation& source,
                                           const std::string& where, SamplerUses& use, std::vector<std::string>& warnings) {
    const tinygltf::Model& model = reader.model();
    std::vector<AnimationChannel> channels;
    for (std::size_t c = 0; c < source.channels.size(); ++c) {
        const tinygltf::AnimationChannel& ch = source.channels[c];
        const std::string w = where + " channel " + str(c);
        if (ch.sampler < 0 || std::size_t(ch.sampler) >= source.samplers.size())
            reader.fail(w + " names sampler " + std::to_string(ch.sampler) + ", which does not exist");
        AnimatedPath path;
        if (ch.target_path == "translation") path = AnimatedPath::Translation;
        else if (ch.target_path == "rotation") path = AnimatedPath::Rotation;
        else if (ch.target_path == "scale") path = AnimatedPath::Scale;
        else if (ch.target_path == "weights") path = AnimatedPath::Weights;
        else {
            warnings.push_back(reader.name() + ": " + w + ": target path '" + ch.target_path + "' is not animated");
            continue;
        }
        if (ch.target_node < 0) continue;  // the specification leaves such a channel to extensions
        if (std::size_t(ch.target_node) >= model.nodes.size())
            reader.fail(w + " targets node " + std::to_string(ch.target_node) + ", which does not exist");
        const tinygltf::Node& node = model.nodes[std::size_t(ch.target_node)];
        if (node.matrix.size() == 16)
            reader.fail(w + " animates node " + std::to_string(ch.target_node) +
                        ", which has a matrix (glTF animates translation, rotation and scale only)");
        std::size_t width = path == AnimatedPath::Rotation ? 4 : 3;
        if (path == AnimatedPath::Weights) {
            width = morphTargetsOf(model, node);
            if (width == 0)
                reader.fail(w + " animates the weights of node " + std::to_string(ch.target_node) +
                            ", whose mesh has no morph targets");
        }
        const std::size_t s = std::size_t(ch.sampler);
        if (use[s] && (use[s]->second != width))
            reader.fail(w + ": sampler " + str(s) + " is used for outputs of different sizes");
        use[s] = std::make_pair(path, width);
        channels.push_back({ch.target_node, path, s});
    }
    return channels;
}

// Key times must increase strictly; an accessor without a view is zeros but for its sparse
// values, so more than one key beyond those cannot increase. Refused before its declared count
// is allocated.
void checkKeyCount(const AccessorReader& reader, int input, const std::string& w) {
    const std::uint64_t keys = reader.checkedCount(input, {TINYGLTF_TYPE_SCALAR}, w);
    if (!reader.hasNoView(input)) return;  // its count is bounded by its view's bytes
    const tinygltf::Accessor& acc = reader.model().accessors[std::size_t(input)];
    const std::uint64_t set = acc.sparse.isSparse ? std::uint64_t(std::max(acc.sparse.count, 0)) : 0;
    if (keys > set + 1)
        reader.fail(w + ": accessor " + std::to_string(input) + " has no buffer view and " + str(set) + " sparse values, so its " +
                    str(keys) + " key times cannot increase strictly");
}

// A sampler as its channels read it (`path`, `width` numbers per key): key times finite and
// strictly increasing, as many finite values as the keys need.
AnimationSampler readSampler(const AccessorReader& reader, const tinygltf::AnimationSampler& src, AnimatedPath path,
                             std::size_t width, const std::string& w) {
    AnimationSampler out;
    out.width = width;
    if (src.interpolation.empty() || src.interpolation == "LINEAR") out.interpolation = Interpolation::Linear;
    else if (src.interpolation == "STEP") out.interpolation = Interpolation::Step;
    else if (src.interpolation == "CUBICSPLINE") out.interpolation = Interpolation::CubicSpline;
    else reader.fail(w + ": interpolation '" + src.interpolation + "' is none of STEP, LINEAR, CUBICSPLINE");
    checkKeyCount(reader, src.input, w + " input");
    for (const glm::dvec4& v : reader.readVectors(src.input, {TINYGLTF_TYPE_SCALAR}, w + " input")) out.times.push_back(v.x);
    if (out.times.empty()) reader.fail(w + ": the input accessor has no keys");
    for (std::size_t k = 0; k < out.times.size(); ++k) {
        if (!std::isfinite(out.times[k])) reader.fail(w + ": key " + str(k) + " has a non-finite time");
        if (k > 0 && !(out.times[k] > out.times[k - 1]))
            reader.fail(w + ": key times must increase strictly (key " + str(k) + " at " + std::to_string(out.times[k]) +
                        " s follows " + std::to_string(out.times[k - 1]) + " s)");
    }
    const bool scalar = path == AnimatedPath::Weights;
    const int type = scalar ? TINYGLTF_TYPE_SCALAR : out.width == 4 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3;
    const std::size_t perKey = (scalar ? out.width : 1) * (out.interpolation == Interpolation::CubicSpline ? 3 : 1);
    // Counted before read: a view-less output's count is declared, not bounded by its bytes.
    if (const std::uint64_t count = reader.checkedCount(src.output, {type}, w + " output"); count != out.times.size() * perKey)
        reader.fail(w + ": the output accessor has " + str(count) + " elements; " + str(out.times.size()) + " keys need " +
                    str(out.times.size() * perKey));
    const std::vector<glm::dvec4> values = reader.readVectors(src.output, {type}, w + " output");
    for (const glm::dvec4& v : values)
        for (std::size_t c = 0; c < (scalar ? 1 : out.width); ++c) {
            if (!std::isfinite(v[int(c)])) reader.fail(w + ": the output has a non-finite number");
            out.values.push_back(v[int(c)]);
        }
    return out;
}

// Scales and rotations keyed as the file has them; a rotation key that is not a unit
// quaternion (beyond the 1% the loader allows a node's rotation) is refused.
void checkRotationKeys(const AccessorReader& reader, const Animation& anim, const std::string& where) {
    for (const AnimationChannel& ch : anim.channels) {
        if (ch.path != AnimatedPath::Rotation) continue;
        const AnimationSampler& smp = anim.samplers[ch.sampler];
        for (std::size_t i = 0; i + 3 < smp.values.size(); i += 4) {
            const double len = std::sqrt(smp.values[i] * smp.values[i] + smp.values[i + 1] * smp.values[i + 1] +
                                         smp.values[i + 2] * smp.values[i + 2] + smp.values[i + 3] * smp.values[i + 3]);
            const bool tangent = smp.interpolation == Interpolation::CubicSpline && (i / 4) % 3 != 1;
            if (!tangent && !(std::abs(len - 1.0) <= 1e-2))
                reader.fail(where + ": sampler " + str(ch.sampler) + " rotates by a quaternion of length " +
                            std::to_string(len) + ", not 1");
        }
    }
}

// Animation `a` of the file: its channels, the samplers they read, its start and end.
Animation readAnimation(const AccessorReader& reader, std::size_t a, std::vector<std::string>& warnings) {
    const tinygltf::Animation& source = reader.model().animations[a];
    const std::string where = "animation " + str(a) + (source.name.empty() ? "" : " '" + source.name + "'");
    Animation anim;
    anim.name = source.name;
    SamplerUses use(source.samplers.size());
    anim.channels = readChannels(reader, source, where, use, warnings);
    anim.samplers.resize(source.samplers.size());
    bool any = false;
    for (std::size_t s = 0; s < source.samplers.size(); ++s) {
        if (!use[s]) continue;  // no channel reads it
        AnimationSampler& sampler = anim.samplers[s];
        sampler = readSampler(reader, source.samplers[s], use[s]->first, use[s]->second, where + " sampler " + str(s));
        anim.start = any ? std::min(anim.start, sampler.times.front()) : sampler.times.front();
        anim.end = any ? std::max(anim.end, sampler.times.back()) : sampler.times.back();
        any = true;
    }
    checkRotationKeys(reader, anim, where);
    return anim;
}

}  // namespace

std::vector<double> sampleAt(const AnimationSampler& sampler, double t, bool quaternion) {
    const std::size_t w = sampler.width;
    const bool cubic = sampler.interpolation == Interpolation::CubicSpline;
    const std::size_t stride = cubic ? 3 * w : w;           // numbers per key
    const std::size_t at = cubic ? w : 0;                   // where a key's value starts
    const KeyInterval i = intervalOf(sampler.times, t);
    const double* v0 = sampler.values.data() + i.k * stride + at;
    std::vector<double> out;
    if (i.last || i.s == 0.0 || sampler.interpolation == Interpolation::Step) {
        out.assign(v0, v0 + w);
    } else if (sampler.interpolation == Interpolation::Linear) {
        const double* v1 = v0 + stride;
        if (quaternion) return slerp(v0, v1, i.s);
        out.resize(w);
        for (std::size_t c = 0; c < w; ++c) out[c] = v0[c] * (1.0 - i.s) + v1[c] * i.s;
    } else {
        // Cubic Hermite spline: the value and out-tangent of key k, the in-tangent and value of
        // key k + 1, the tangents scaled by the interval's length.
        const double* b0 = v0 + w;                 // out-tangent of key k
        const double* a1 = v0 + stride - w;        // in-tangent of key k + 1
        const double* v1 = v0 + stride;
        const double s = i.s, s2 = s * s, s3 = s2 * s;
        const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
        out.resize(w);
        for (std::size_t c = 0; c < w; ++c)
            out[c] = h00 * v0[c] + h10 * i.span * b0[c] + h01 * v1[c] + h11 * i.span * a1[c];
    }
    if (quaternion) normalizeQuaternion(out);
    return out;
}

std::vector<Animation> readAnimations(const AccessorReader& reader, std::vector<std::string>& warnings) {
    std::vector<Animation> out;
    for (std::size_t a = 0; a < reader.model().animations.size(); ++a) out.push_back(readAnimation(reader, a, warnings));
    return out;
}

int chooseAnimation(const std::vector<Animation>& animations, const std::string& choice, const AccessorReader& reader) {
    if (choice.empty()) return -1;
    for (std::size_t i = 0; i < animations.size(); ++i)
        if (!animations[i].name.empty() && animations[i].name == choice) return int(i);
    if (const std::optional<int> index = indexChoice(choice); index && *index < int(animations.size())) return *index;
    std::string list;
    for (std::size_t i = 0; i < animations.size(); ++i)
        list += (list.empty() ? "" : ", ") + str(i) + (animations[i].name.empty() ? "" : " '" + animations[i].name + "'");
    reader.fail("no animation is called or numbered '" + choice + "' (" +
                (list.empty() ? std::string("the file has none") : "the file has " + list) + ")");
}

std::vector<NodePose> poseAt(const std::vector<Animation>& animations, int chosen, double t, std::size_t nodeCount) {
    std::vector<NodePose> pose(nodeCount);
    for (std::size_t a = 0; a < animations.size(); ++a) {
        if (chosen >= 0 && int(a) != chosen) continue;
        const Animation& anim = animations[a];
        for (const AnimationChannel& ch : anim.channels) {
            const AnimationSampler& sampler = anim.samplers[ch.sampler];
            const std::vector<double> v = sampleAt(sampler, t, ch.path == AnimatedPath::Rotation);
            NodePose& p = pose[std::size_t(ch.node)];
            switch (ch.path) {
                case AnimatedPath::Translation: p.translation = glm::dvec3(v[0], v[1], v[2]); break;
                case AnimatedPath::Rotation: p.rotation = glm::dquat(v[3], v[0], v[1], v[2]); break;
                case AnimatedPath::Scale: p.scale = glm::dvec3(v[0], v[1], v[2]); break;
                case AnimatedPath::Weights: p.weights = v; break;
            }
        }
    }
    return pose;
}

}  // namespace dacrt::gltf
