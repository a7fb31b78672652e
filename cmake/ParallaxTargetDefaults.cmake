# Compile settings shared by every Parallax target. Applied per target, never through
# CMAKE_CXX_FLAGS, so that dependencies and consumers are not affected.
function(parallax_target_defaults target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF POSITION_INDEPENDENT_CODE ON)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion
                                           -Wshadow -Wnon-virtual-dtor -Wold-style-cast)
  # g++ 12 reports -Wrestrict inside libstdc++ for std::string operator+ (GCC PR 105329, a
  # false positive fixed in g++ 13).
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    target_compile_options(${target} PRIVATE -Wno-restrict)
  endif()
  if(PARALLAX_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(PARALLAX_NATIVE_ARCH)
    target_compile_options(${target} PRIVATE -march=native)
  endif()
  if(PARALLAX_FUZZ)
    # Coverage feedback from every Parallax library, not only the fuzz targets themselves.
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
  if(PARALLAX_SANITIZE)
    # A finding must fail the test that caused it: UBSan would otherwise report and go on.
    target_compile_options(${target} PUBLIC -fsanitize=${PARALLAX_SANITIZE} -fno-omit-frame-pointer
                                            -fno-sanitize-recover=all)
    target_link_options(${target} PUBLIC -fsanitize=${PARALLAX_SANITIZE})
  endif()
endfunction()

# A library for one engine folder: parallax_<name> with the alias parallax::<name>.
function(parallax_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(parallax_${name} STATIC ${ARG_SOURCES})
  add_library(parallax::${name} ALIAS parallax_${name})
  target_include_directories(parallax_${name} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>)
  target_link_libraries(parallax_${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  parallax_target_defaults(parallax_${name})
endfunction()
