# Script mode: validates one GLSL file with glslangValidator, following `#include` lines
# (GL_GOOGLE_include_directive): preprocess with -E, then compile the result. Writes STAMP on success.
#   cmake -DVALIDATOR=... -DSHADER=... -DSTAMP=... -P validate_shader.cmake
get_filename_component(dir ${SHADER} DIRECTORY)
get_filename_component(name ${SHADER} NAME)
get_filename_component(stamp_dir ${STAMP} DIRECTORY)
set(preprocessed ${stamp_dir}/${name})
execute_process(COMMAND ${VALIDATOR} -E -I${dir} ${SHADER} OUTPUT_FILE ${preprocessed} ERROR_VARIABLE err
                RESULT_VARIABLE result WORKING_DIRECTORY ${dir})
if(NOT result EQUAL 0)
  file(READ ${preprocessed} log)
  message(FATAL_ERROR "shader ${name}: preprocessing failed:\n${log}${err}")
endif()
execute_process(COMMAND ${VALIDATOR} ${preprocessed} OUTPUT_VARIABLE log ERROR_VARIABLE err RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "shader ${name}: glslangValidator failed:\n${log}${err}")
endif()
file(WRITE ${STAMP} "ok\n")
