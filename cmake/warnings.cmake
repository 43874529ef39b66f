# One place for compiler warnings; every parallax target links parallax_warnings.
add_library(parallax_warnings INTERFACE)
target_compile_options(parallax_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align -Wunused
  -Woverloaded-virtual -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough)
