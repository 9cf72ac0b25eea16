# Optional proxsuite (dense QP, header-only on Eigen), installed by `pip install proxsuite` under the
# venv's site-packages/cmeel.prefix. Sets NLOSLOC_HAVE_PROXSUITE (ON/OFF); proxsuite::proxsuite when found.
#
# The cmeel prefix goes into HINTS of this one call, not into CMAKE_PREFIX_PATH: a cmeel-eigen installed
# in that prefix would otherwise shadow Debian's Eigen for every later find_package. Eigen3 must already be
# found (proxsuite's package reuses the existing Eigen3::Eigen target). Only the core component is asked
# for (the default also asks for the vectorized ones, which need simde).
include_guard(GLOBAL)

set(NLOSLOC_HAVE_PROXSUITE OFF)
if(NOT TARGET Eigen3::Eigen)
  message(FATAL_ERROR "nloslocProxsuite.cmake: find Eigen3 before proxsuite")
endif()

# An interpreter whose site-packages may hold cmeel.prefix: the one given, else the project's .venv,
# else python3 from PATH.
set(_nlosloc_py "")
if(Python_EXECUTABLE)
  set(_nlosloc_py "${Python_EXECUTABLE}")
elseif(EXISTS "${PROJECT_SOURCE_DIR}/.venv/bin/python")
  set(_nlosloc_py "${PROJECT_SOURCE_DIR}/.venv/bin/python")
else()
  find_program(_nlosloc_py_prog NAMES python3 python)
  if(_nlosloc_py_prog)
    set(_nlosloc_py "${_nlosloc_py_prog}")
  endif()
endif()

set(_nlosloc_cmeel_hints "")
if(_nlosloc_py)
  execute_process(COMMAND "${_nlosloc_py}" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])"
                  OUTPUT_VARIABLE _nlosloc_purelib OUTPUT_STRIP_TRAILING_WHITESPACE
                  RESULT_VARIABLE _nlosloc_rc ERROR_QUIET)
  if(_nlosloc_rc EQUAL 0 AND EXISTS "${_nlosloc_purelib}/cmeel.prefix")
    list(APPEND _nlosloc_cmeel_hints "${_nlosloc_purelib}/cmeel.prefix")
  endif()
endif()

find_package(proxsuite CONFIG QUIET COMPONENTS proxsuite HINTS ${_nlosloc_cmeel_hints})
if(proxsuite_FOUND AND TARGET proxsuite::proxsuite)
  set(NLOSLOC_HAVE_PROXSUITE ON)
  message(STATUS "nlosloc: proxsuite ${proxsuite_VERSION} found (${proxsuite_DIR})")
else()
  message(STATUS "nlosloc: proxsuite not found (optional; pip install proxsuite into .venv)")
endif()
