# One interface target carrying the project's warning flags; every skinlab target links it.
add_library(skinlab_warnings INTERFACE)
target_compile_options(skinlab_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow=local -Wno-missing-field-initializers)
if(SKINLAB_WERROR)
  target_compile_options(skinlab_warnings INTERFACE -Werror)
endif()
