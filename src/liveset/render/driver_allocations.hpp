// Mesa's drivers, loaded by EGL/GLX when a context is created and unloaded when it goes, keep a
// few small blocks until exit; LeakSanitizer reports them but cannot attribute them once the
// driver is unmapped. In AddressSanitizer builds the software driver is therefore pinned in memory
// (RTLD_NODELETE): its globals stay mapped and still point at those blocks, so LeakSanitizer finds
// them reachable and needs no suppression for them.
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#endif

namespace liveset::render {

inline void keep_driver_mapped() {
#if defined(__SANITIZE_ADDRESS__)
    static const bool once = [] {
        for (const char* path : {"/usr/lib/x86_64-linux-gnu/dri/swrast_dri.so", "/usr/lib/x86_64-linux-gnu/libEGL_mesa.so.0",
                                 "/usr/lib/x86_64-linux-gnu/libGLX_mesa.so.0"})
            dlopen(path, RTLD_LAZY | RTLD_NODELETE);
        return true;
    }();
    (void)once;
#endif
}

}  // namespace liveset::render
