# Included by the top-level CMakeLists.txt: the option TETSEG_BUILD_PYTHON (docs/python.md),
# ON by default when pybind11 and a Python interpreter with NumPy and headers are found.
set(TETSEG_PYTHON_FOUND OFF)
if(NOT Python_EXECUTABLE AND EXISTS /usr/bin/python3)
  # When the first python3 on PATH has no NumPy (e.g. pyenv's), use the system one, for which
  # Debian's python3-numpy and python3-dev are installed.
  find_program(TETSEG_PATH_PYTHON NAMES python3 NO_CACHE)
  execute_process(COMMAND ${TETSEG_PATH_PYTHON} -c "import numpy" RESULT_VARIABLE numpy_missing
                  OUTPUT_QUIET ERROR_QUIET)
  if(numpy_missing)
    set(Python_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "Python interpreter")
  endif()
endif()
find_package(Python 3.8 COMPONENTS Interpreter Development.Module NumPy QUIET)
if(Python_FOUND)
  find_package(pybind11 2.6 CONFIG QUIET)
  if(pybind11_FOUND)
    set(TETSEG_PYTHON_FOUND ON)
  endif()
endif()
option(TETSEG_BUILD_PYTHON "Build the Python package (pybind11; docs/python.md)" ${TETSEG_PYTHON_FOUND})
if(NOT TETSEG_BUILD_PYTHON AND NOT TETSEG_PYTHON_FOUND)
  message(STATUS "Python package off: needs pybind11 and a Python with NumPy and headers "
                 "(choose one with -DPython_EXECUTABLE=...; docs/python.md)")
endif()
