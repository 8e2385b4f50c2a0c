#include "app/output_paths.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include <fcntl.h>
#include <unistd.h>

#include "core/errors.hpp"
#include "core/image_io.hpp"

namespace dacrt {
namespace {

namespace fs = std::filesystem;

std::string lowerExtension(const std::string& path) {
    std::string e = fs::path(path).extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return e;
}

std::string sameFileKey(const std::string& path) {
    std::error_code ec;
    const fs::path canonical = fs::weakly_canonical(fs::absolute(path), ec);
    return ec ? path : canonical.string();
}

// Whether a file can be made in the folder: tried with a probe, removed at once (permission
// bits say too little: root passes access() for /proc, where nothing can be created).
bool canCreateFileIn(const fs::path& folder) {
    const fs::path probe = folder / (".dacrt-probe-" + std::to_string(getpid()));
    const int fd = open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (fd < 0) return false;
    close(fd);
    unlink(probe.c_str());
    return true;
}

void checkOne(const PlannedOutput& o) {
    const std::string where = o.option + " " + o.path + ": ";
    std::error_code ec;
    if (fs::is_directory(o.path, ec)) throw InputError(where + "is a folder, not a file");
    const fs::path parent = fs::path(o.path).parent_path().empty() ? fs::path(".") : fs::path(o.path).parent_path();
    if (!fs::exists(parent, ec)) throw InputError(where + "the folder " + parent.string() + " does not exist");
    if (!fs::is_directory(parent, ec)) throw InputError(where + parent.string() + " is not a folder");
    if (!canCreateFileIn(parent)) throw InputError(where + "the folder " + parent.string() + " cannot be written");
    if (fs::exists(o.path, ec) && access(o.path.c_str(), W_OK) != 0) throw InputError(where + "the file cannot be written");
    const std::string ext = lowerExtension(o.path);
    switch (o.format) {
        case OutputFormat::Exr:
            if (ext != ".exr")
                throw InputError(where + "AOVs are 8 channels of 32-bit data (Z, N.X, N.Y, N.Z, primId, hit, u, v), "
                                 "which only OpenEXR holds: name a .exr file (a PNG takes 1 to 4 8- or 16-bit "
                                 "channels; -o writes the shaded image)");
            break;
        case OutputFormat::Image: {
            if (ext.empty()) throw InputError(where + "needs an extension that names the image format (.png, .exr, ...)");
            const std::string problem = imageWriterProblem(o.path);
            if (!problem.empty()) throw InputError(where + "cannot write '" + ext + "' images (" + problem + ")");
            break;
        }
        case OutputFormat::Text: break;
    }
}

}  // namespace

void checkOutputs(const std::vector<PlannedOutput>& outputs, const std::vector<std::string>& inputs) {
    std::vector<std::pair<std::string, std::string>> seen;  // key, "option path"
    for (const std::string& in : inputs) seen.emplace_back(sameFileKey(in), "the input " + in);
    for (const PlannedOutput& o : outputs) {
        if (o.path.empty()) continue;
        checkOne(o);
        const std::string key = sameFileKey(o.path);
        for (const auto& [other, what] : seen)
            if (other == key) throw InputError(o.option + " " + o.path + ": the same file as " + what);
        seen.emplace_back(key, o.option + " " + o.path);
    }
}

}  // namespace dacrt
