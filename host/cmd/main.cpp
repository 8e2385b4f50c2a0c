#include "cmd/cli.hpp"

int main(int argc, char** argv) { return dacrt::runCli(argc, argv); }
