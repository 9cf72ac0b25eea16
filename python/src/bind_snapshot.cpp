/// \file bind_snapshot.cpp
/// nlosloc.snapshot (being written; see bind.hpp).
#include "bind.hpp"

void bind_snapshot(pybind11::module_& m) { (void)m; }
