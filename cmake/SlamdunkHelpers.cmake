# Helpers shared by every module, tool and test folder.

# slamdunk_add_module(NAME SOURCES a.cpp ... PUBLIC_DEPS t1 ... PRIVATE_DEPS t2 ...)
# Builds library slamdunk_<NAME> (alias slamdunk::<NAME>) from modules/<NAME>/{include,src}.
function(slamdunk_add_module NAME)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  set(target slamdunk_${NAME})
  add_library(${target} SHARED ${ARG_SOURCES})
  add_library(slamdunk::${NAME} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${NAME})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${target} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  slamdunk_use_pch(${target} lib)
  install(TARGETS ${target} EXPORT slamdunk-targets
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()

# slamdunk_add_tool(NAME SOURCES a.cpp ... DEPS t1 ...): a command-line program.
function(slamdunk_add_tool NAME)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${NAME} ${ARG_SOURCES})
  target_link_libraries(${NAME} PRIVATE ${ARG_DEPS})
  target_compile_options(${NAME} PRIVATE -Wall -Wextra)
  slamdunk_use_pch(${NAME} exe)
  set_target_properties(${NAME} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bin)
  install(TARGETS ${NAME} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endfunction()

# Folder names listed in SLAMDUNK_SKIP_DIRS are left out of the build (partial builds, e.g. a
# machine without EGL can skip "synthetic"). Everything is built by default.
set(SLAMDUNK_SKIP_DIRS "" CACHE STRING "Module/tool/test folder names to leave out of the build")

# slamdunk_add_subdirectories(): adds every direct subfolder that has a CMakeLists.txt, or, with
# ORDER a b c, those folders in that order.
function(slamdunk_add_subdirectories)
  cmake_parse_arguments(ARG "" "" "ORDER" ${ARGN})
  if(ARG_ORDER)
    set(dirs ${ARG_ORDER})
  else()
    file(GLOB entries LIST_DIRECTORIES true RELATIVE ${CMAKE_CURRENT_SOURCE_DIR}
      ${CMAKE_CURRENT_SOURCE_DIR}/*)
    list(SORT entries)
    set(dirs ${entries})
  endif()
  foreach(dir ${dirs})
    if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${dir}/CMakeLists.txt AND NOT dir IN_LIST SLAMDUNK_SKIP_DIRS)
      add_subdirectory(${dir})
    endif()
  endforeach()
endfunction()
