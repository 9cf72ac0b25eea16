/// \file bind_rbpf.cpp
/// nlosloc.rbpf (being written; see bind.hpp).
#include "bind.hpp"

void bind_rbpf(pybind11::module_& m) { (void)m; }
