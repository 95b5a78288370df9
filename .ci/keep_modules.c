// Preloaded into the sanitizer stage's test processes (packaging/test-sanitizers.sh): dlclose keeps every module
// loaded. LeakSanitizer reports at exit, after the Vulkan loader has unloaded Mesa's lavapipe driver; the stacks of
// the driver's process-lifetime allocations then name no module, and .ci/lsan.supp's suppressions (libvulkan_lvp.so,
// libLLVM) cannot match them. With the driver still loaded they do. Test-only: nothing of Tyndall links it.
int dlclose(void* handle) {
    (void)handle;
    return 0;
}
