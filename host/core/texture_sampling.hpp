#pragma once
// Texture lookups as glTF defines them: coordinates through KHR_texture_transform, wrapped by
// the sampler's modes, nearest or bilinear between texel centres, sRGB texels to linear.
// (No mipmaps: minification samples like magnification.)
#include <glm/glm.hpp>

#include "core/scene.hpp"

namespace dacrt {

// Linear RGBA of the binding's texture at uv (glTF's texture coordinates: (0, 0) is the
// image's top-left corner). sRGB: the texture holds colour (base colour) rather than data.
glm::vec4 sampleTexture(const Texture& texture, const TextureBinding& binding, glm::vec2 uv, bool sRGB = true);

}  // namespace dacrt
