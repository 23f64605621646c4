// Linked into the programs of sanitizer builds only (cmake/Sanitizers.cmake): dlclose() does
// nothing, so that libraries loaded at run time (Vulkan drivers and layers, OpenNI2 drivers)
// stay mapped until LeakSanitizer's check at exit. Their globals then still count as roots, and
// a leak inside them is reported with the library's name, which sanitizers/lsan.supp can match.
// A definition in the executable takes precedence over libc's for every shared library.
extern "C" int dlclose(void*) { return 0; }
