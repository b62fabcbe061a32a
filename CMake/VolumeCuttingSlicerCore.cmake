# Slicer Core mode: build every Qt-free library of the extension with VTK's
# module system against the slicer-core wheels (see Docs/BuildModes.md).
#
# Expected cache variables (Utilities/Setup/bootstrap.py writes them to
# build/platform.cmake, passed with -C):
#   VTK_DIR                  assembled VTK 9.6.2 SDK (Debian sid, re-pointed at the wheel)
#   VTK_WHEEL_LIBRARY_DIR    site-packages/vtkmodules of the project's virtual environment
#   slicer_core_sdk_DIR      the (patched) slicer-core-sdk CMake package
#   Python3_EXECUTABLE       the virtual environment's interpreter

include(GNUInstallDirs)
include(CTest)

set(CMAKE_CXX_STANDARD 17)
set(CMAKE_CXX_STANDARD_REQUIRED ON)
set(CMAKE_CXX_EXTENSIONS OFF)
set(CMAKE_POSITION_INDEPENDENT_CODE ON)
set(BUILD_SHARED_LIBS ON)

# The vtk and slicer-core wheels are built with the old libstdc++ string ABI:
# every translation unit that touches their classes must use it too.
add_compile_definitions(_GLIBCXX_USE_CXX11_ABI=0)

find_package(Python3 3.11 EXACT REQUIRED COMPONENTS Interpreter Development.Module)
if(NOT EXISTS "${VTK_WHEEL_LIBRARY_DIR}/libvtkCommonCore.so")
  message(FATAL_ERROR "VTK_WHEEL_LIBRARY_DIR must name the vtk wheel's vtkmodules folder; run Utilities/vc setup")
endif()
get_filename_component(VolumeCutting_SITE_PACKAGES "${VTK_WHEEL_LIBRARY_DIR}" DIRECTORY)
set(VolumeCutting_WHEEL_RUNTIME_DIRS
  "${VTK_WHEEL_LIBRARY_DIR}"
  "${VolumeCutting_SITE_PACKAGES}/slicer_core"
  "${VolumeCutting_SITE_PACKAGES}/slicer_core/third_party.libs"
  )

find_package(VTK 9.6 REQUIRED)
find_package(slicer_core_sdk REQUIRED COMPONENTS MRMLCore MRMLLogic BaseLogic SegmentationCore SegmentationsModuleMRML)

# The slicer-core libraries find their own dependencies only next to each
# other (RPATH $ORIGIN): use DT_RPATH, which applies to transitive
# dependencies too, and list the wheel folders for build-tree executables.
add_link_options("LINKER:--disable-new-dtags")
set(CMAKE_BUILD_RPATH "${VolumeCutting_WHEEL_RUNTIME_DIRS}")
# Installed into the wheel beside vtkmodules/ and slicer_core/.
set(CMAKE_INSTALL_RPATH "$ORIGIN;$ORIGIN/../vtkmodules;$ORIGIN/../slicer_core;$ORIGIN/../slicer_core/third_party.libs")

include(VolumeCuttingMacros)
include(VolumeCuttingSanitizers)

set(MODULE_NAME VolumeCutting)
string(TOUPPER ${MODULE_NAME} MODULE_NAME_UPPER)

vtk_module_find_modules(volumecutting_module_files
  "${CMAKE_CURRENT_SOURCE_DIR}/Modules"
  "${CMAKE_CURRENT_SOURCE_DIR}/VolumeCutting")
vtk_module_scan(
  MODULE_FILES ${volumecutting_module_files}
  WANT_BY_DEFAULT ON
  PROVIDES_MODULES volumecutting_modules
  ENABLE_TESTS ${BUILD_TESTING}
  )

set(VolumeCutting_PYTHON_PACKAGE slicer_volumecutting)
vtk_module_build(
  MODULES ${volumecutting_modules}
  INSTALL_HEADERS OFF
  INSTALL_EXPORT VolumeCutting
  LIBRARY_DESTINATION ${VolumeCutting_PYTHON_PACKAGE}
  RUNTIME_DESTINATION ${VolumeCutting_PYTHON_PACKAGE}
  ARCHIVE_DESTINATION ${VolumeCutting_PYTHON_PACKAGE}
  HIERARCHY_DESTINATION ${VolumeCutting_PYTHON_PACKAGE}/hierarchy
  TEST_DIRECTORY_NAME Testing
  )

option(VolumeCutting_WRAP_PYTHON "Python-wrap the libraries (off for sanitizer builds, which run C++ tests only)" ON)
if(NOT VolumeCutting_WRAP_PYTHON)
  return()
endif()

vtk_module_wrap_python(
  MODULES ${volumecutting_modules}
  PYTHON_PACKAGE ${VolumeCutting_PYTHON_PACKAGE}
  MODULE_DESTINATION .
  INSTALL_HEADERS OFF
  BUILD_STATIC OFF
  TARGET VolumeCutting::Python
  )

# Python side of the wheel: the package init, the jump pad that makes the
# classes appear under `slicer.` as in desktop Slicer, and the Qt-free Python
# libraries of the scripted modules.
install(FILES Utilities/Python/slicer_volumecutting/__init__.py DESTINATION ${VolumeCutting_PYTHON_PACKAGE})
install(FILES Utilities/Python/slicer/slicer_volumecutting.py DESTINATION slicer)
install(DIRECTORY Modules/Scripted/VolumeCuttingTools/VolumeCuttingLib DESTINATION .
  PATTERN "__pycache__" EXCLUDE)
# Data the library reads (VolumeCuttingLib.config.toolconfig finds it here, in
# desktop Slicer's module resources and in the source tree).
install(FILES Resources/Presets/VolumeCuttingToolPresets.json DESTINATION VolumeCuttingLib/Resources/Presets)
install(FILES Resources/Sessions/HeadCTMastoidectomy.json DESTINATION VolumeCuttingLib/Resources/Sessions)
