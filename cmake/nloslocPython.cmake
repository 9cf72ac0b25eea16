# Python and pybind11 for the extension nlosloc._core.
#
# pybind11 must be PyPI's (>= 2.12): Debian's pybind11-dev 2.10 builds modules that crash with numpy 2
# (DESIGN.md). So pybind11_DIR is taken from the interpreter (`python -m pybind11 --cmakedir`) unless
# given, the version is required, and a pybind11 found under /usr is rejected.
# Interpreter: Python_EXECUTABLE if given (scikit-build-core gives it), else the project's .venv.
include_guard(GLOBAL)

if(NOT Python_EXECUTABLE AND NOT SKBUILD AND EXISTS "${PROJECT_SOURCE_DIR}/.venv/bin/python")
  set(Python_EXECUTABLE "${PROJECT_SOURCE_DIR}/.venv/bin/python" CACHE FILEPATH "Python interpreter")
endif()
find_package(Python 3.9 REQUIRED COMPONENTS Interpreter Development.Module)

# Recomputed on every configure unless the user set pybind11_DIR: pip's isolated build environments
# (a new temporary path each time) would otherwise leave a stale path in a reused build directory.
if(NOT pybind11_DIR OR pybind11_DIR MATCHES "-NOTFOUND$" OR pybind11_DIR STREQUAL _NLOSLOC_PYBIND11_DIR_AUTO
   OR NOT EXISTS "${pybind11_DIR}")
  execute_process(COMMAND "${Python_EXECUTABLE}" -m pybind11 --cmakedir
                  OUTPUT_VARIABLE _nlosloc_pybind11_dir OUTPUT_STRIP_TRAILING_WHITESPACE
                  RESULT_VARIABLE _nlosloc_rc ERROR_QUIET)
  if(NOT _nlosloc_rc EQUAL 0)
    message(FATAL_ERROR "nlosloc: `${Python_EXECUTABLE} -m pybind11 --cmakedir` failed; "
                        "install pybind11>=2.12 from PyPI into that interpreter (scripts/bootstrap.sh does)")
  endif()
  set(pybind11_DIR "${_nlosloc_pybind11_dir}" CACHE PATH "pybind11 CMake package (PyPI's)" FORCE)
  set(_NLOSLOC_PYBIND11_DIR_AUTO "${_nlosloc_pybind11_dir}" CACHE INTERNAL "pybind11_DIR set by nlosloc")
endif()

set(PYBIND11_FINDPYTHON ON)
find_package(pybind11 2.12 CONFIG REQUIRED)
if(pybind11_DIR MATCHES "^/usr/(lib|share)/")
  message(FATAL_ERROR "nlosloc: pybind11 found at ${pybind11_DIR} (a system package). Use PyPI's "
                      "pybind11>=2.12 (`python -m pybind11 --cmakedir`); Debian's breaks with numpy 2.")
endif()
message(STATUS "nlosloc: pybind11 ${pybind11_VERSION} from ${pybind11_DIR}, Python ${Python_VERSION}")
