// The extension module `liveset._liveset`: C++ errors become Python exceptions carrying their
// one-line messages, and the worker-thread limit. The Python package (liveset/__init__.py) wraps
// these functions with images, docstrings and nibabel interop.
#include <memory>
#include <new>

#include "bindings.hpp"
#include "cli_common.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/segment/segmentation.hpp"

namespace {
std::shared_ptr<void> g_thread_limit;  // tbb::global_control while a limit is set
}

PYBIND11_MODULE(_liveset, m) {
    namespace pyb = pybind11;
    m.doc() = "liveset's C++ core (use the `liveset` package, not this module)";
    static pyb::exception<liveset::ImageIoError> io_error(m, "ImageIOError", PyExc_OSError);
    pyb::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const liveset::ImageIoError& e) {
            io_error(e.what());
        } catch (const liveset::cli::UsageError& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        } catch (const std::out_of_range& e) {
            PyErr_SetString(PyExc_IndexError, e.what());
        }
    });
    // std::invalid_argument -> ValueError, std::bad_alloc -> MemoryError: pybind11's own translations.
    m.def("set_threads", [](int threads) {
        if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: all cores)");
        g_thread_limit.reset();
        g_thread_limit = liveset::cli::limit_threads(threads);
    }, pyb::arg("threads"));
    m.attr("__version__") = LIVESET_VERSION;
    // The step `liveset segment` takes by default (segment_step(): the thin-front rule on or off),
    // which segment() and Session default to.
    m.attr("DEFAULT_THIN_FRONTS") = liveset::segment_step().thin_fronts;
    liveset::py::register_core(m);
    liveset::py::register_session(m);
}
