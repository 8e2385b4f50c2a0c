#pragma once
// The lights a frame is shaded by: the scene's KHR_lights_punctual lights, those the command
// line names (--light), or a default key light; or none, the headlight preview.
#include <string>
#include <vector>

#include "core/camera.hpp"
#include "core/scene.hpp"

namespace dacrt {

// A --light value: "point:X,Y,Z[:INTENSITY[:R,G,B]]" (candela), "directional:DX,DY,DZ[:INTENSITY[:R,G,B]]"
// (the direction the light travels; lux), or "headlight". Throws InputError naming the value.
struct LightSpec {
    bool headlight = false;
    Light light;
};
LightSpec parseLightSpec(const std::string& text);

// What the frame is lit by when the scene has no lights and --light names none: from above the
// camera's left shoulder. Seen from outside the scene's box, a directional light; from inside
// (a room, whose walls a directional light could not pass), a point light above and left of the
// camera, kept inside the box.
Light defaultKeyLight(const Camera& camera, const Box& sceneBox);

// The frame's lights: the --light values when given (any "headlight" among them: none, the
// preview), else the scene's, else the default key light. `headlight` tells which.
std::vector<Light> frameLights(const Scene& scene, const Camera& camera, const Box& sceneBox,
                               const std::vector<std::string>& specs, bool& headlight);

}  // namespace dacrt
