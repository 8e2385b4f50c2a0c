#include "cmd/cli.hpp"
#include "core/system_memory.hpp"

int main(int argc, char** argv) {
    dacrt::reuseFreedMemory();
    return dacrt::runCli(argc, argv);
}
