#pragma once
// Materials as the shaded preview reads them: base colour factor, base colour texture (its
// image decoded by OpenImageIO, its sampler, KHR_texture_transform), doubleSided. An image
// that is missing or does not decode is a warning naming it, and its materials keep their base
// colour factor. Internal to the glTF loader.
#include <string>

#include <tiny_gltf.h>

#include "core/gltf_accessors.hpp"
#include "core/scene.hpp"

namespace dacrt::gltf {

// tinygltf's image hook: keeps the encoded bytes of data-URI images in image->image (decoded
// later, only where a material uses them). Buffer-view images are read later, through the
// reader's checked ranges (tinygltf hands over an unchecked pointer for them).
bool keepEncodedImage(tinygltf::Image* image, int index, std::string* err, std::string* warn, int, int,
                      const unsigned char* bytes, int size, void*);

struct ImageSource {
    std::string baseDir;  // for images by uri
    bool readFiles = true;  // false: memory input, where images by uri are not read
};

// Fills scene.materials (in file order) and scene.textures; warnings go to scene.warnings.
void readMaterials(const AccessorReader& reader, const ImageSource& source, Scene& scene);

}  // namespace dacrt::gltf
