/// \file bind_bounds.cpp
/// nlosloc.bounds (being written; see bind.hpp).
#include "bind.hpp"

void bind_bounds(pybind11::module_& m) { (void)m; }
