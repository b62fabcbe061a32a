# Build helpers that let one layer CMakeLists.txt serve both build modes:
# Slicer extension mode (Slicer's macros) and Slicer Core mode (VTK modules).

#-----------------------------------------------------------------------------
# volumecutting_add_library(<kit>
#   VTK_MODULE <name in vtk.module> EXPORT_DIRECTIVE <macro> SRCS <files...>
#   [PRIVATE_SRCS <files...>] [INCLUDE_DIRECTORIES <dirs...>]
#   [TARGET_LIBRARIES <libs...>] [PRIVATE_LIBRARIES <targets...>])
#
# SRCS are classes (<class>.cxx with <class>.h), installed and wrapped; a
# class may live in a subfolder of the layer (<folder>/<class>.cxx), whose
# folder is then on the include path of the library and its users.
# PRIVATE_SRCS are compiled into the library only: no class, not wrapped.
# PRIVATE_LIBRARIES are libraries from outside VTK and Slicer (pkg-config
# imported targets) that the library links in both modes.
#
# Every library exposes <kit>Export.h defining <EXPORT_DIRECTIVE>, as Slicer's
# macros generate it; in Core mode the header forwards to the VTK module's.
# TARGET_LIBRARIES are used in extension mode only: in Core mode the
# dependencies come from vtk.module.
function(volumecutting_add_library kit)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "VTK_MODULE;EXPORT_DIRECTIVE" "SRCS;PRIVATE_SRCS;INCLUDE_DIRECTORIES;TARGET_LIBRARIES;PRIVATE_LIBRARIES")
  set(class_folders)
  foreach(source IN LISTS arg_SRCS arg_PRIVATE_SRCS)
    get_filename_component(folder "${source}" DIRECTORY)
    if(folder)
      list(APPEND class_folders "${CMAKE_CURRENT_SOURCE_DIR}/${folder}")
    endif()
  endforeach()
  list(REMOVE_DUPLICATES class_folders)
  if(VolumeCutting_BUILD_WITH_SLICER_CORE)
    set(classes)
    foreach(source IN LISTS arg_SRCS)
      if(source MATCHES "^(.*)\\.cxx$")
        list(APPEND classes ${CMAKE_MATCH_1})
      endif()
    endforeach()
    string(REGEX REPLACE "_EXPORT$" "" export_prefix "${arg_EXPORT_DIRECTIVE}")
    slicercore_generate_module_wrapper(HEADER_NAME ${kit}Export.h OUTPUT_VAR export_header)
    set(private_headers ${arg_PRIVATE_SRCS})
    list(FILTER private_headers INCLUDE REGEX "\\.h$")
    set(private_sources ${arg_PRIVATE_SRCS})
    list(FILTER private_sources EXCLUDE REGEX "\\.h$")
    vtk_module_add_module(${arg_VTK_MODULE}
      EXPORT_MACRO_PREFIX ${export_prefix}
      CLASSES ${classes}
      HEADERS ${export_header}
      SOURCES ${private_sources}
      PRIVATE_HEADERS ${private_headers}
      )
    foreach(folder IN LISTS class_folders)
      vtk_module_include(${arg_VTK_MODULE} PUBLIC "$<BUILD_INTERFACE:${folder}>")
    endforeach()
    if(arg_PRIVATE_LIBRARIES)
      vtk_module_link(${arg_VTK_MODULE} PRIVATE ${arg_PRIVATE_LIBRARIES})
    endif()
  else()
    # Slicer's wrapping takes every <name>.cxx that has a <name>.h.
    set_source_files_properties(${arg_PRIVATE_SRCS} PROPERTIES WRAP_EXCLUDE ON)
    SlicerMacroBuildModuleLogic(
      NAME ${kit}
      EXPORT_DIRECTIVE ${arg_EXPORT_DIRECTIVE}
      INCLUDE_DIRECTORIES ${arg_INCLUDE_DIRECTORIES} ${class_folders}
      SRCS ${arg_SRCS} ${arg_PRIVATE_SRCS}
      TARGET_LIBRARIES ${arg_TARGET_LIBRARIES} ${arg_PRIVATE_LIBRARIES}
      )
  endif()
endfunction()

#-----------------------------------------------------------------------------
# volumecutting_add_cxx_tests(<kit> TESTS <names...> [LIBRARIES <libs...>])
#
# One test driver per library, one test per <name>.cxx defining
# `int <name>(int argc, char* argv[])`. The last argument of each test is a
# writable temporary directory. As Slicer's WITH_VTK_ERROR_OUTPUT_CHECK does,
# a test fails if it logs VTK warnings or errors it did not expect (tests
# that provoke errors assert them with TESTING_OUTPUT_ASSERT_* from vtkAddon).
function(volumecutting_add_cxx_tests kit)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "TESTS;LIBRARIES")
  set(sources)
  foreach(test_name IN LISTS arg_TESTS)
    list(APPEND sources ${test_name}.cxx)
  endforeach()
  set(temporary_dir "${CMAKE_BINARY_DIR}/Testing/Temporary")
  file(MAKE_DIRECTORY "${temporary_dir}")
  if(VolumeCutting_BUILD_WITH_SLICER_CORE)
    set(CMAKE_TESTDRIVER_BEFORE_TESTMAIN
      "  vtkOutputWindow::SetInstance(vtkTestingOutputWindow::GetInstance());\n  vtkTestingOutputWindow::GetInstance()->ResetNumberOfLoggedMessages();\n")
    set(CMAKE_TESTDRIVER_AFTER_TESTMAIN
      "  if (result == 0 && vtkTestingOutputWindow::GetInstance()->GetNumberOfLoggedWarningErrorMessages() > 0)\n  {\n    std::cerr << \"Test failed: it logged unexpected VTK warnings or errors\" << std::endl;\n    result = 1;\n  }\n")
    create_test_sourcelist(driver_sources ${kit}CxxTests.cxx ${sources}
      EXTRA_INCLUDE vtkTestingOutputWindow.h)
    add_executable(${kit}CxxTests ${driver_sources})
    target_link_libraries(${kit}CxxTests PRIVATE ${arg_LIBRARIES} vtkAddon)
    foreach(test_name IN LISTS arg_TESTS)
      add_test(NAME ${kit}.${test_name} COMMAND ${kit}CxxTests ${test_name} "${temporary_dir}")
      # The wheel's libvtkAddon.so has a RUNPATH that misses vtkmodules/: in
      # Python the libraries are loaded already, here the loader needs the path.
      string(REPLACE ";" ":" runtime_path "${VolumeCutting_WHEEL_RUNTIME_DIRS}")
      set_tests_properties(${kit}.${test_name} PROPERTIES
        LABELS "cxx;${kit}"
        ENVIRONMENT "LD_LIBRARY_PATH=${runtime_path}")
    endforeach()
  else()
    set(KIT ${kit})
    slicerMacroConfigureModuleCxxTestDriver(
      NAME ${kit}
      SOURCES ${sources}
      TARGET_LIBRARIES ${arg_LIBRARIES}
      WITH_VTK_DEBUG_LEAKS_CHECK
      WITH_VTK_ERROR_OUTPUT_CHECK
      )
    foreach(test_name IN LISTS arg_TESTS)
      simple_test(${test_name} "${temporary_dir}")
    endforeach()
  endif()
endfunction()
