/* LD_PRELOAD shim for .ci/sanitize: dlclose does nothing, so the Vulkan driver and layers stay
 * mapped until the process ends. Without it the loader unloads them at vkDestroyInstance, and
 * LeakSanitizer (which runs at exit) then reports every block the driver still held through
 * its own globals as leaked, from an "<unknown module>" no suppression can name. */
int dlclose(void *handle) {
    (void)handle;
    return 0;
}
