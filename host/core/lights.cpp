#include "core/lights.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.hpp"

namespace dacrt {
namespace {

std::vector<std::string> split(const std::string& text, char separator) {
    std::vector<std::string> parts;
    std::stringstream in(text);
    std::string part;
    while (std::getline(in, part, separator)) parts.push_back(part);
    if (!text.empty() && text.back() == separator) parts.emplace_back();
    return parts;
}

double number(const std::string& text, const std::string& spec) {
    std::size_t used = 0;
    double v = 0.0;
    try {
        v = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size() || !std::isfinite(v))
        throw InputError("--light " + spec + ": '" + text + "' is not a finite number");
    return v;
}

glm::dvec3 triple(const std::string& text, const std::string& spec, const char* what) {
    const std::vector<std::string> parts = split(text, ',');
    if (parts.size() != 3) throw InputError("--light " + spec + ": the " + std::string(what) + " needs three numbers x,y,z");
    return {number(parts[0], spec), number(parts[1], spec), number(parts[2], spec)};
}

// Intensities and colours become float32: a value beyond this would be infinite there.
constexpr double kLargestLightValue = 1e30;

double lightValue(double v, const std::string& spec, const char* what) {
    if (v < 0.0) throw InputError("--light " + spec + ": the " + std::string(what) + " is negative");
    if (v > kLargestLightValue) throw InputError("--light " + spec + ": the " + std::string(what) + " exceeds 1e30");
    return v;
}

// The unit direction of d, scaled by its largest component first so that no length
// overflows or underflows; zero only for the zero vector.
glm::dvec3 unitDirection(const glm::dvec3& d) {
    const double largest = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
    return largest == 0.0 ? glm::dvec3(0.0) : glm::normalize(d / largest);
}

}  // namespace

LightSpec parseLightSpec(const std::string& text) {
    LightSpec spec;
    if (text == "headlight") {
        spec.headlight = true;
        return spec;
    }
    const std::vector<std::string> parts = split(text, ':');
    const std::string usage = " (point:X,Y,Z[:INTENSITY[:R,G,B]], directional:DX,DY,DZ[:INTENSITY[:R,G,B]] or headlight)";
    if (parts.size() < 2 || parts.size() > 4 || (parts[0] != "point" && parts[0] != "directional"))
        throw InputError("--light " + text + ": not a light" + usage);
    Light& light = spec.light;
    light.name = "--light " + text;
    if (parts[0] == "point") {
        light.type = LightType::Point;
        light.position = triple(parts[1], text, "position");
        if (glm::any(glm::greaterThan(glm::abs(light.position), glm::dvec3(kMaxCoordinate))))
            throw InputError("--light " + text + ": the position lies beyond " + std::to_string(kMaxCoordinate));
    } else {
        light.type = LightType::Directional;
        light.direction = unitDirection(triple(parts[1], text, "direction"));
        if (light.direction == glm::dvec3(0.0)) throw InputError("--light " + text + ": the direction is zero");
    }
    if (parts.size() >= 3) light.intensity = float(lightValue(number(parts[2], text), text, "intensity"));
    if (parts.size() == 4) {
        const glm::dvec3 c = triple(parts[3], text, "colour");
        light.color = glm::vec3(lightValue(c.r, text, "colour"), lightValue(c.g, text, "colour"),
                                lightValue(c.b, text, "colour"));
    }
    return spec;
}

Light defaultKeyLight(const Camera& camera, const Box& box) {
    const glm::dvec3 right = glm::normalize(glm::cross(camera.forward, camera.up));
    Light key;
    key.name = "key light (default)";
    const glm::dvec3 lo(box.lo), hi(box.hi), extent = hi - lo;
    const bool inside = glm::all(glm::greaterThan(camera.eye, lo)) && glm::all(glm::lessThan(camera.eye, hi));
    if (!inside) {
        key.type = LightType::Directional;
        key.direction = glm::normalize(0.8 * camera.forward - 1.0 * camera.up + 0.5 * right);
        key.intensity = 3.0f;
        return key;
    }
    const double size = glm::length(extent);
    key.type = LightType::Point;
    key.position = glm::clamp(camera.eye + 0.25 * size * camera.up - 0.15 * size * right + 0.1 * size * camera.forward,
                              lo + 0.1 * extent, hi - 0.1 * extent);
    key.intensity = float(size * size);  // about 1 lux at the scene's size: the exposure scales it anyway
    return key;
}

std::vector<Light> frameLights(const Scene& scene, const Camera& camera, const Box& sceneBox,
                               const std::vector<std::string>& specs, bool& headlight) {
    headlight = false;
    std::vector<Light> lights;
    for (const std::string& s : specs) {
        const LightSpec spec = parseLightSpec(s);
        if (spec.headlight) headlight = true;
        else lights.push_back(spec.light);
    }
    if (headlight) {
        if (!lights.empty()) throw InputError("--light headlight is the unlit preview; it takes no other --light");
        return {};
    }
    if (!specs.empty()) return lights;
    for (const Light& l : scene.lights)
        if (l.type != LightType::Directional && glm::any(glm::greaterThan(glm::abs(l.position), glm::dvec3(kMaxCoordinate))))
            throw InputError("light '" + l.name + "' lies beyond " + std::to_string(kMaxCoordinate) +
                             ", the largest coordinate dacrt traces (the scene's vertices obey the same limit)");
    if (!scene.lights.empty()) return scene.lights;
    return {defaultKeyLight(camera, sceneBox)};
}

}  // namespace dacrt
