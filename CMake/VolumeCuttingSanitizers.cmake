# VolumeCutting_SANITIZE: a list of sanitizers for a checking build, e.g.
# "address;undefined" or "thread". The C++ tests then run instrumented; the
# wheel libraries they load are not, so only our own code is checked.
set(VolumeCutting_SANITIZE "" CACHE STRING "Sanitizers to build with (address, undefined, thread)")
if(VolumeCutting_SANITIZE)
  string(REPLACE ";" "," _volumecutting_sanitizers "${VolumeCutting_SANITIZE}")
  add_compile_options(-fsanitize=${_volumecutting_sanitizers} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=${_volumecutting_sanitizers})
endif()
