#include "core/exr_header.hpp"

#include <cstring>
#include <fstream>

#include "core/errors.hpp"

namespace dacrt {
namespace {

constexpr std::uint32_t kExrMagic = 20000630;
constexpr std::uint32_t kMultiPart = 0x1000;  // version field: several headers, an empty one last
constexpr std::uint32_t kLongNames = 0x400;   // version field: names up to 255 bytes, not 31

// Reads the attributes of the headers from just after the version field.
class HeaderWalker {
public:
    HeaderWalker(std::ifstream& in, const std::string& path, std::uint64_t fileSize, std::size_t maxName)
        : in_(in), path_(path), size_(fileSize), maxName_(maxName) {}

    // One header's attributes; false when the header was empty (a multi-part file's end).
    bool header() {
        for (bool first = true;; first = false) {
            const std::string name = text("an attribute name");
            if (name.empty()) return !first;
            const std::string type = text("the type of attribute " + name);
            std::int32_t declared = 0;
            if (!in_.read(reinterpret_cast<char*>(&declared), 4)) fail("it ends inside the size of attribute " + name);
            const std::uint64_t at = std::uint64_t(in_.tellg());
            if (declared < 0 || std::uint64_t(declared) > size_ - at)
                fail("attribute " + name + " (" + type + ") declares " + std::to_string(declared) + " bytes, " +
                     std::to_string(size_ - at) + " are left in the file");
            in_.seekg(std::streamoff(declared), std::ios::cur);
        }
    }

private:
    [[noreturn]] void fail(const std::string& what) const { throw InputError(path_ + ": not a readable OpenEXR header: " + what); }

    std::string text(const std::string& what) {
        std::string s;
        for (char c = 0; in_.get(c) && c != '\0';) {
            if (s.size() == maxName_) fail(what + " is longer than " + std::to_string(maxName_) + " bytes");
            s.push_back(c);
        }
        if (!in_) fail("it ends inside " + what);
        return s;
    }

    std::ifstream& in_;
    const std::string& path_;
    std::uint64_t size_;
    std::size_t maxName_;
};

}  // namespace

void checkExrHeaderSizes(const std::string& path, std::uint64_t fileSize) {
    std::ifstream in(path, std::ios::binary);
    std::uint32_t magic = 0, version = 0;
    if (!in.read(reinterpret_cast<char*>(&magic), 4) || magic != kExrMagic) return;
    if (!in.read(reinterpret_cast<char*>(&version), 4))
        throw InputError(path + ": not a readable OpenEXR header: it ends inside its version");
    HeaderWalker walker(in, path, fileSize, (version & kLongNames) ? 255 : 31);
    if (!(version & kMultiPart)) {
        walker.header();
        return;
    }
    while (walker.header()) {
    }
}

}  // namespace dacrt
