# RELIGHT_SANITIZE (e.g. "address,undefined", set by the asan preset) instruments every target
# that follows, ours and the tests alike. Undefined behaviour aborts the test that meets it
# instead of printing a line nobody reads.
if(NOT RELIGHT_SANITIZE)
  return()
endif()
add_compile_options(-fsanitize=${RELIGHT_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
add_link_options(-fsanitize=${RELIGHT_SANITIZE})
# GCC 12 reports -Wmaybe-uninitialized inside libstdc++'s <regex> when it is instrumented (a
# false positive of the sanitizer's extra control flow); the uninstrumented debug build keeps the
# warning for our code.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  add_compile_options(-Wno-maybe-uninitialized)
endif()

# LeakSanitizer checks at exit, after the Vulkan loader and OpenNI2 have unloaded the drivers and
# layers they dlopen()ed; memory those libraries still held in their globals then looks leaked,
# from "<unknown module>", which no suppression can name. Programs of a sanitizer build therefore
# keep every library loaded (sanitizers/keep_libraries_loaded.cpp): what is reachable is not
# reported, and a real leak names its library.
add_library(relight_keep_libraries_loaded OBJECT ${CMAKE_CURRENT_LIST_DIR}/../sanitizers/keep_libraries_loaded.cpp)
# Shared libraries call dlclose() through the executable's definition only if it is exported.
target_link_options(relight_keep_libraries_loaded INTERFACE "LINKER:--export-dynamic-symbol=dlclose")

# ThreadSanitizer reads its suppressions and options from the program itself
# (sanitizers/tsan_default_options.cpp), so that gtest's test discovery at build time and the CLI
# under the app tests apply them as ctest does.
if(RELIGHT_SANITIZE MATCHES "thread")
  target_sources(relight_keep_libraries_loaded PRIVATE ${CMAKE_CURRENT_LIST_DIR}/../sanitizers/tsan_default_options.cpp)
  target_compile_definitions(relight_keep_libraries_loaded
    PRIVATE RELIGHT_TSAN_SUPPRESSIONS="${PROJECT_SOURCE_DIR}/sanitizers/tsan.supp")
endif()
