/// \file bind_situation.cpp
/// nlosloc.situation (being written; see bind.hpp).
#include "bind.hpp"

void bind_situation(pybind11::module_& m) { (void)m; }
