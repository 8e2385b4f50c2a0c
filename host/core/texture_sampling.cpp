#include "core/texture_sampling.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace dacrt {
namespace {

const std::array<float, 256>& srgbToLinear() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) {
            const double c = i / 255.0;
            t[std::size_t(i)] = float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
        }
        return t;
    }();
    return table;
}

// Texel index along one axis for integer coordinate i (may be outside [0, size)).
int wrapped(long long i, int size, TextureWrap wrap) {
    const long long n = size;
    switch (wrap) {
        case TextureWrap::ClampToEdge: return int(std::clamp<long long>(i, 0, n - 1));
        case TextureWrap::MirroredRepeat: {
            const long long period = 2 * n;
            long long k = ((i % period) + period) % period;
            return int(k < n ? k : period - 1 - k);
        }
        case TextureWrap::Repeat:
        default: return int(((i % n) + n) % n);
    }
}

glm::vec4 texel(const Texture& t, int x, int y, bool sRGB) {
    const std::uint8_t* p = t.rgba.data() + (std::size_t(y) * std::size_t(t.width) + std::size_t(x)) * 4;
    const auto& lut = srgbToLinear();
    if (!sRGB) return glm::vec4(p[0], p[1], p[2], p[3]) / 255.0f;
    return {lut[p[0]], lut[p[1]], lut[p[2]], float(p[3]) / 255.0f};
}

}  // namespace

glm::vec4 sampleTexture(const Texture& texture, const TextureBinding& binding, glm::vec2 uv, bool sRGB) {
    if (texture.width <= 0 || texture.height <= 0) return glm::vec4(1.0f);
    const glm::vec3 t = binding.transform * glm::vec3(uv, 1.0f);
    // Texel space, with texel centres at integers. Coordinates far outside [0, 1] keep only
    // their position within one period (repeat and mirrored repeat both repeat after 2), or
    // are clamped near the edge, so that texel indices stay small.
    auto reduce = [](float c, TextureWrap wrap) {
        if (!std::isfinite(c)) return 0.0f;
        return wrap == TextureWrap::ClampToEdge ? std::clamp(c, -1.0f, 2.0f) : c - 2.0f * std::floor(c * 0.5f);
    };
    const double x = double(reduce(t.x, binding.wrapS)) * texture.width - 0.5,
                 y = double(reduce(t.y, binding.wrapT)) * texture.height - 0.5;
    if (binding.nearest) {
        const long long ix = (long long)std::floor(x + 0.5), iy = (long long)std::floor(y + 0.5);
        return texel(texture, wrapped(ix, texture.width, binding.wrapS), wrapped(iy, texture.height, binding.wrapT), sRGB);
    }
    const double fx = std::floor(x), fy = std::floor(y);
    const float ax = float(x - fx), ay = float(y - fy);
    const long long x0 = (long long)fx, y0 = (long long)fy;
    const int xs[2] = {wrapped(x0, texture.width, binding.wrapS), wrapped(x0 + 1, texture.width, binding.wrapS)};
    const int ys[2] = {wrapped(y0, texture.height, binding.wrapT), wrapped(y0 + 1, texture.height, binding.wrapT)};
    const glm::vec4 top = glm::mix(texel(texture, xs[0], ys[0], sRGB), texel(texture, xs[1], ys[0], sRGB), ax);
    const glm::vec4 bottom = glm::mix(texel(texture, xs[0], ys[1], sRGB), texel(texture, xs[1], ys[1], sRGB), ax);
    return glm::mix(top, bottom, ay);
}

}  // namespace dacrt
