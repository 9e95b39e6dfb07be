# focsim_io: focsim's scenario parser and SVG plot writer (host only,
# standard C).  include()d from tools/CMakeLists.txt, before focsim, so that
# focsim and the tests in tests/focsim can both link it.
add_library(focsim_io STATIC
  ${CMAKE_CURRENT_LIST_DIR}/scenario.c
  ${CMAKE_CURRENT_LIST_DIR}/svgplot.c)
target_include_directories(focsim_io PUBLIC ${CMAKE_CURRENT_LIST_DIR})
target_compile_options(focsim_io PRIVATE ${FOC_HOST_WARNINGS})
set_property(TARGET focsim_io PROPERTY C_STANDARD 11)
target_link_libraries(focsim_io PUBLIC m)
