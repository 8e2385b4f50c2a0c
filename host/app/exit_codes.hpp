#pragma once
// The exit codes of every dacrt command, in one place (also in --help and the README).
namespace dacrt {

enum ExitCode : int {
    kExitSuccess = 0,
    kExitCheckFailed = 1,     // the command ran, and what it checks does not hold (stress, compare --fail-on)
    kExitBadInput = 2,        // a file, option or scene was refused (InputError); nothing was written
    kExitValidation = 3,      // --validate: the Vulkan validation layers reported errors
    kExitDeviceFailure = 4,   // a Vulkan call failed (VulkanError): the driver or device
    kExitInternalError = 5,   // a bug in dacrt (InternalError or anything unexpected): please report it
};

// The table above as text, for --help.
inline const char* exitCodeHelp() {
    return "Exit codes: 0 success; 1 a check the command ran does not hold (stress, compare --fail-on); 2 bad input "
           "or options "
           "(one message, nothing traced); 3 Vulkan validation errors under --validate; 4 a Vulkan call "
           "failed; 5 an internal error in dacrt (please report it).";
}

}  // namespace dacrt
