# Every third-party library mneedle uses, found once here. .ci/install-deps.sh installs them.
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(CGAL 5.5 REQUIRED)
find_package(assimp REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(tomlplusplus REQUIRED)
find_package(Threads REQUIRED)
# SHA-256 of every input in an output's provenance (core/src/base/provenance.cpp)
find_package(OpenSSL 3 REQUIRED COMPONENTS Crypto)

# PLplot (figures, its svg driver) ships pkg-config data, no CMake config that works on its own.
find_package(PkgConfig REQUIRED)
pkg_check_modules(PLPLOT REQUIRED IMPORTED_TARGET plplot)

# Debian ships two NLopt configs (nlopt, nlopt_cxx) and either may be found first;
# NLOPT_LIBRARIES names the target of whichever it was, and both serve <nlopt.hpp>.
find_package(NLopt REQUIRED)

# CHOLMOD has no CMake config on Debian 12: build an imported target by hand.
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY cholmod)
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig)
if(CHOLMOD_INCLUDE_DIR AND CHOLMOD_LIBRARY AND SUITESPARSECONFIG_LIBRARY)
  add_library(mneedle_cholmod INTERFACE)
  target_include_directories(mneedle_cholmod SYSTEM INTERFACE ${CHOLMOD_INCLUDE_DIR})
  target_link_libraries(mneedle_cholmod INTERFACE ${CHOLMOD_LIBRARY} ${SUITESPARSECONFIG_LIBRARY})
  target_compile_definitions(mneedle_cholmod INTERFACE MNEEDLE_HAVE_CHOLMOD=1)
  set(MNEEDLE_HAVE_CHOLMOD ON)
  message(STATUS "mneedle: CHOLMOD found (${CHOLMOD_LIBRARY})")
else()
  add_library(mneedle_cholmod INTERFACE)
  set(MNEEDLE_HAVE_CHOLMOD OFF)
  message(STATUS "mneedle: CHOLMOD not found, using Eigen's sparse solvers")
endif()

# MPI for screening on a cluster (screen --mpi), only when asked for: the C bindings are all it
# uses (optimize/src/screening_mpi.cpp).
if(MNEEDLE_MPI)
  find_package(MPI REQUIRED COMPONENTS C)
  message(STATUS "mneedle: MPI ${MPI_C_VERSION} (${MPI_C_LIBRARIES})")
endif()
