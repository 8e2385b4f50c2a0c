#include "app/output_paths.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <functional>
#include <optional>
#include <unordered_map>

#include <fcntl.h>
#include <unistd.h>

#include "core/errors.hpp"
#include "core/image_io.hpp"
#include "core/output_target.hpp"

namespace dacrt {
namespace {

namespace fs = std::filesystem;

std::string lowerExtension(const std::string& path) {
    std::string e = fs::path(path).extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return e;
}

bool isDeviceOrFifo(const std::string& path) {
    std::error_code ec;
    const fs::file_status s = fs::status(path, ec);
    return !ec && (s.type() == fs::file_type::character || s.type() == fs::file_type::fifo);
}

// What is known of a folder outputs go to, found once for all the outputs in it.
struct FolderFacts {
    std::string problem;    // empty: files can be made there
    std::string canonical;  // for the same-file check
};

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

FolderFacts factsOf(const fs::path& folder) {
    std::error_code ec;
    if (!fs::exists(folder, ec)) return {"the folder " + folder.string() + " does not exist", {}};
    if (!fs::is_directory(folder, ec)) return {folder.string() + " is not a folder", {}};
    if (!canCreateFileIn(folder)) return {"the folder " + folder.string() + " cannot be written", {}};
    const fs::path canonical = fs::weakly_canonical(fs::absolute(folder), ec);
    return {{}, ec ? folder.string() : canonical.string()};
}

// The checks of every output, with what is the same for many of them (a folder's facts, an
// extension's image writer) found once: a frame range names up to millions of files.
class OutputChecker {
public:
    // The file the output writes (a link's target), as a key equal for every name of it; empty
    // for a device or FIFO.
    std::string check(const PlannedOutput& o) {
        const std::string where = o.option + " " + o.path + ": ";
        OutputTarget target;
        try {
            target = resolveOutputTarget(o.path);
        } catch (const InputError& e) {
            throw InputError(o.option + " " + e.what());
        }
        checkFormat(o, where);
        if (target.writeThrough) {
            if (access(target.path.c_str(), W_OK) != 0) throw InputError(where + "the device or FIFO cannot be written");
            return {};  // outputs may share a device or FIFO: each is written whole, in turn
        }
        const fs::path file(target.path);
        const fs::path parent = file.parent_path().empty() ? fs::path(".") : file.parent_path();
        auto [it, fresh] = folders_.try_emplace(parent.string());
        if (fresh) it->second = factsOf(parent);
        if (!it->second.problem.empty()) throw InputError(where + it->second.problem);
        if (target.exists && access(target.path.c_str(), W_OK) != 0) throw InputError(where + "the file cannot be written");
        return (fs::path(it->second.canonical) / file.filename()).string();
    }

private:
    void checkFormat(const PlannedOutput& o, const std::string& where) {
        const std::string ext = lowerExtension(encodingNameFor(o.path, o.format));
        switch (o.format) {
            case OutputFormat::Exr:
                if (ext != ".exr")
                    throw InputError(where + "AOVs are 8 channels of 32-bit data (Z, N.X, N.Y, N.Z, primId, hit, u, v), "
                                     "which only OpenEXR holds: name a .exr file (a PNG takes 1 to 4 8- or 16-bit "
                                     "channels; -o writes the shaded image)");
                break;
            case OutputFormat::Image: {
                if (ext.empty()) throw InputError(where + "needs an extension that names the image format (.png, .exr, ...)");
                auto [it, fresh] = writers_.try_emplace(ext);
                if (fresh) it->second = imageWriterProblem(encodingNameFor(o.path, o.format));
                if (!it->second.empty()) throw InputError(where + "cannot write '" + ext + "' images (" + it->second + ")");
                break;
            }
            case OutputFormat::Text: break;
        }
    }

    std::unordered_map<std::string, FolderFacts> folders_;
    std::unordered_map<std::string, std::string> writers_;  // extension: why no writer (empty: one)
};

}  // namespace

std::string encodingNameFor(const std::string& path, OutputFormat format) {
    if (format == OutputFormat::Text || !fs::path(path).extension().empty()) return path;
    // A link without an extension (/dev/stdout redirected to a file) goes by its file's.
    std::error_code ec;
    if (fs::is_symlink(path, ec))
        if (const fs::path target = fs::canonical(path, ec); !ec && !target.extension().empty()) return target.string();
    if (!isDeviceOrFifo(path)) return path;
    return path + (format == OutputFormat::Exr ? ".exr" : ".png");
}

void checkOutputs(std::size_t count, const std::function<PlannedOutput(std::size_t)>& outputAt,
                  const std::vector<std::string>& inputs) {
    // Every file's key hashed with its ordinal (16 bytes a name: a range may name millions of
    // files); equal hashes are then compared by their keys, made again.
    OutputChecker checker;
    auto inputKey = [](const std::string& in) {
        std::error_code ec;
        const fs::path canonical = fs::weakly_canonical(fs::absolute(in), ec);
        return ec ? in : canonical.string();
    };
    std::vector<std::pair<std::size_t, std::size_t>> hashes;  // hash, ordinal (inputs after outputs)
    for (std::size_t i = 0; i < count; ++i) {
        const PlannedOutput o = outputAt(i);
        if (o.path.empty()) continue;
        if (const std::string key = checker.check(o); !key.empty()) hashes.emplace_back(std::hash<std::string>{}(key), i);
    }
    for (std::size_t k = 0; k < inputs.size(); ++k) hashes.emplace_back(std::hash<std::string>{}(inputKey(inputs[k])), count + k);
    std::sort(hashes.begin(), hashes.end());
    auto describe = [&](std::size_t ordinal) {
        if (ordinal >= count) return "the input " + inputs[ordinal - count];
        const PlannedOutput o = outputAt(ordinal);
        return o.option + " " + o.path + (o.context.empty() ? "" : " (" + o.context + ")");
    };
    auto keyOf = [&](std::size_t ordinal) {
        return ordinal >= count ? inputKey(inputs[ordinal - count]) : OutputChecker().check(outputAt(ordinal));
    };
    // Of the clashes, the one a run writing in order would meet first: an output that is an
    // input (inputs order after outputs), else the pair whose later output comes first.
    struct Clash {
        std::size_t when, named, other;
    };
    std::optional<Clash> clash;
    for (std::size_t i = 1; i < hashes.size(); ++i) {
        if (hashes[i].first != hashes[i - 1].first) continue;
        std::size_t end = i;
        while (end < hashes.size() && hashes[end].first == hashes[i - 1].first) ++end;
        std::vector<std::pair<std::size_t, std::string>> run;  // a run of equal hashes, keys made again
        for (std::size_t j = i - 1; j < end; ++j) run.emplace_back(hashes[j].second, keyOf(hashes[j].second));
        for (std::size_t x = 0; x < run.size(); ++x)
            for (std::size_t y = x + 1; y < run.size(); ++y) {
                const std::size_t first = std::min(run[x].first, run[y].first), second = std::max(run[x].first, run[y].first);
                if (run[x].second != run[y].second || first >= count) continue;  // inputs may share a file
                const Clash c = second >= count ? Clash{0, first, second} : Clash{second + 1, second, first};
                if (!clash || c.when < clash->when) clash = c;
            }
        i = end - 1;
    }
    if (clash) throw InputError(describe(clash->named) + ": the same file as " + describe(clash->other));
}

void checkOutputs(const std::vector<PlannedOutput>& outputs, const std::vector<std::string>& inputs) {
    checkOutputs(outputs.size(), [&outputs](std::size_t i) { return outputs[i]; }, inputs);
}

}  // namespace dacrt
