#pragma once
// An OpenEXR file's headers, walked before OpenImageIO hands the file to OpenEXR: OpenEXR 3.1
// allocates the size an attribute declares before reading it (a string attribute is then read
// a byte at a time), so a few bytes declaring 2^31 - 1 take seconds and gigabytes to refuse.
#include <cstdint>
#include <string>

namespace dacrt {

// Throws InputError naming the file and the attribute when a header attribute declares a size
// past the end of the file, or a header does not end inside it. Files that are not OpenEXR (no
// magic number) pass: they are not read here.
void checkExrHeaderSizes(const std::string& path, std::uint64_t fileSize);

}  // namespace dacrt
