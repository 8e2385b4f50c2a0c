#include "app/stale_temporaries.hpp"

#include <cctype>
#include <cerrno>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include <signal.h>
#include <unistd.h>

namespace dacrt {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kPartial = ".partial-";

struct Temporary {
    std::string finalName;  // STEM.EXT
    pid_t pid = 0;
};

// ".STEM.partial-PID-N.EXT" (core/atomic_file.cpp's naming) read back; none for any other name.
std::optional<Temporary> parseTemporary(const std::string& name) {
    const std::size_t at = name.rfind(kPartial);
    if (name.empty() || name[0] != '.' || at == std::string::npos || at < 1) return std::nullopt;
    std::size_t i = at + kPartial.size();
    const std::size_t pidStart = i;
    while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i]))) ++i;
    if (i == pidStart || i - pidStart > 9 || i >= name.size() || name[i] != '-') return std::nullopt;
    const long pid = std::stol(name.substr(pidStart, i - pidStart));
    const std::size_t counterStart = ++i;
    while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i]))) ++i;
    if (i == counterStart || (i < name.size() && name[i] != '.')) return std::nullopt;
    if (pid <= 0) return std::nullopt;
    return Temporary{name.substr(1, at - 1) + name.substr(i), pid_t(pid)};
}

// kill(pid, 0) delivers nothing and fails with ESRCH only when no such process exists; EPERM
// means it exists under another user.
bool processAlive(pid_t pid) { return ::kill(pid, 0) == 0 || errno == EPERM; }

}  // namespace

std::vector<std::string> removeStaleTemporaries(const std::vector<std::string>& outputs) {
    std::map<fs::path, std::set<std::string>> namesByFolder;
    for (const std::string& o : outputs) {
        if (o.empty()) continue;
        const fs::path p(o);
        namesByFolder[p.parent_path().empty() ? fs::path(".") : p.parent_path()].insert(p.filename().string());
    }
    std::vector<std::string> removed;
    for (const auto& [folder, names] : namesByFolder) {
        std::error_code ec;
        for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
            const std::string name = it->path().filename().string();
            const std::optional<Temporary> t = parseTemporary(name);
            if (!t || !names.count(t->finalName) || t->pid == ::getpid() || processAlive(t->pid)) continue;
            std::error_code removeError;
            if (fs::remove(it->path(), removeError)) removed.push_back(it->path().string());
        }
    }
    return removed;
}

}  // namespace dacrt
