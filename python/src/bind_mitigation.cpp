/// \file bind_mitigation.cpp
/// nlosloc.mitigation (being written; see bind.hpp).
#include "bind.hpp"

void bind_mitigation(pybind11::module_& m) { (void)m; }
