# The Python module is built with Debian's pybind11 for Debian's interpreter (/usr/bin/python3, the
# one python3-numpy installs into) unless Python_EXECUTABLE (or Python3_EXECUTABLE) names another.
# Without pybind11 or the Python headers it is skipped. Sets LACUNA_PYTHON_FOUND and
# LACUNA_PYTHON_INSTALL_DIR, relative to the install prefix: where that interpreter looks under the
# prefix (lib/python3.X/dist-packages on Debian, so the default prefix /usr/local puts the package on
# its path), else lib/python3.X/site-packages (a prefix of one's own then goes on PYTHONPATH).
set(LACUNA_PYTHON_FOUND OFF)
if(NOT Python_EXECUTABLE)
  if(Python3_EXECUTABLE)
    set(Python_EXECUTABLE "${Python3_EXECUTABLE}" CACHE FILEPATH "The Python interpreter the module is built for")
  elseif(EXISTS /usr/bin/python3)
    set(Python_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "The Python interpreter the module is built for")
  endif()
endif()
find_package(Python 3.8 COMPONENTS Interpreter Development.Module)
if(Python_FOUND)
  set(PYBIND11_FINDPYTHON ON)
  find_package(pybind11 2.6 CONFIG QUIET)
endif()
if(Python_FOUND AND pybind11_FOUND)
  set(LACUNA_PYTHON_FOUND ON)
  set(_lacuna_site "lib/python${Python_VERSION_MAJOR}.${Python_VERSION_MINOR}/site-packages")
  execute_process(COMMAND ${Python_EXECUTABLE} -c "import sysconfig; print(sysconfig.get_path('platlib'))"
                  OUTPUT_VARIABLE _lacuna_platlib OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  string(FIND "${_lacuna_platlib}" "${CMAKE_INSTALL_PREFIX}/" _lacuna_at)
  if(_lacuna_platlib AND _lacuna_at EQUAL 0)
    file(RELATIVE_PATH _lacuna_site "${CMAKE_INSTALL_PREFIX}" "${_lacuna_platlib}")
  endif()
  set(LACUNA_PYTHON_INSTALL_DIR "${_lacuna_site}" CACHE PATH "Where cmake --install puts the package lacuna")
  execute_process(COMMAND ${Python_EXECUTABLE} -c "import numpy" RESULT_VARIABLE _lacuna_numpy OUTPUT_QUIET ERROR_QUIET)
  if(NOT _lacuna_numpy EQUAL 0)
    message(WARNING "${Python_EXECUTABLE} has no numpy (Debian: python3-numpy); the module builds but needs it to import")
  endif()
  message(STATUS "Python module: for ${Python_EXECUTABLE} (${Python_VERSION}), pybind11 ${pybind11_VERSION}")
else()
  message(STATUS "Python module: not built (needs pybind11-dev and python3-dev)")
endif()
