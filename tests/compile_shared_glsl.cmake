# Compiles one shared header as GLSL: a compute shader that includes it, validated for Vulkan. DEFINE, if set, is a
# macro defined before the include.
get_filename_component(stem ${HEADER} NAME_WE)
file(MAKE_DIRECTORY ${WORK_DIR})
set(src ${WORK_DIR}/${stem}.comp)
set(define "")
if(DEFINE)
  set(define "#define ${DEFINE}\n")
endif()
file(WRITE ${src} "#version 460\n#extension GL_GOOGLE_include_directive : require\n${define}#include \"shared/${stem}.h\"\nlayout(local_size_x = 1) in;\nvoid main() {}\n")
execute_process(COMMAND ${GLSLANG} -V --target-env vulkan1.2 -I${INCLUDE_DIR} ${src} -o ${WORK_DIR}/${stem}.spv
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${HEADER} does not compile as GLSL${define}:\n${out}${err}")
endif()
