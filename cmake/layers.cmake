# The layers of smtcal (README.md, "Layout"): one folder and one static
# library each, bottom first. A layer links the layers it is declared to use
# (BELOW) and so sees them and everything they use; it never sees a higher
# one.
#
# How the build enforces it: a layer's headers are reachable only through an
# include root of its own, build/layers/<layer>/, which holds one symbolic
# link, <layer> -> the source folder. A target gets the include roots of the
# layers it links and no other, so `#include "backend/..."` in passes/ does
# not compile ("No such file or directory"). The project's source root is on
# no include path. tests/layering_test.cmake checks the same rule on the
# sources themselves, so a test names the offending line.


# The include root of one folder: build/layers/<name>/<name> -> <source>/<name>.
function(smtcal_include_root name out_var)
  set(root ${PROJECT_BINARY_DIR}/layers/${name})
  file(MAKE_DIRECTORY ${root})
  file(CREATE_LINK ${PROJECT_SOURCE_DIR}/${name} ${root}/${name} SYMBOLIC)
  set(${out_var} ${root} PARENT_SCOPE)
endfunction()

# smtcal_add_layer(<layer> [BELOW <layer>...] [PUBLIC_LIBS ...] [PRIVATE_LIBS ...])
# Every .cpp under <layer>/ (sub-folders included) becomes smtcal_<layer>.
# The rule "<layer>:<below>,<below>" is kept in the global property
# SMTCAL_LAYER_RULES for tests/layering_test.cmake.
function(smtcal_add_layer layer)
  cmake_parse_arguments(ARG "" "" "BELOW;PUBLIC_LIBS;PRIVATE_LIBS" ${ARGN})
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/${layer}/*.cpp)
  list(SORT sources)
  add_library(smtcal_${layer} STATIC ${sources})
  smtcal_include_root(${layer} root)
  target_include_directories(smtcal_${layer} PUBLIC ${root})
  target_compile_options(smtcal_${layer} PRIVATE ${SMTCAL_WARNINGS})
  foreach(below IN LISTS ARG_BELOW)
    target_link_libraries(smtcal_${layer} PUBLIC smtcal_${below})
  endforeach()
  list(JOIN ARG_BELOW "," below_text)
  set_property(GLOBAL APPEND PROPERTY SMTCAL_LAYER_RULES "${layer}:${below_text}")
  target_link_libraries(smtcal_${layer} PUBLIC ${ARG_PUBLIC_LIBS} PRIVATE ${ARG_PRIVATE_LIBS})
endfunction()
