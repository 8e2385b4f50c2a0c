#pragma once
// A glTF image's data: URI read where tinygltf leaves it: tinygltf decodes base64 URIs of a few
// media types only (PNG, JPEG, BMP, GIF, octet-stream), and hands any other one (image/webp of
// EXT_texture_webp, image/ktx2) on as a file name.
#include <string>
#include <vector>

namespace dacrt {

// The bytes of "data:[MEDIATYPE];base64,DATA" (RFC 2397, base64 of RFC 4648 with its padding).
// Empty, with `why` set, for a URI that is not base64 or whose data does not decode.
std::vector<unsigned char> dataUriBytes(const std::string& uri, std::string& why);

}  // namespace dacrt
