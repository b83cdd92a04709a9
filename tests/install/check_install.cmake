# Installs the built tree into a scratch prefix, builds the README example against it with
# find_package(batchcol CONFIG), runs it and checks its output. Invoked by ctest (see tests/CMakeLists.txt).
set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
foreach(step
    "${CMAKE_COMMAND};--install;${BUILD_DIR};--prefix;${prefix}"
    "${CMAKE_COMMAND};-S;${SOURCE_DIR}/tests/install/consumer;-B;${WORK_DIR}/consumer;-DCMAKE_PREFIX_PATH=${prefix};-DCMAKE_EXE_LINKER_FLAGS=${LINK_FLAGS}"
    "${CMAKE_COMMAND};--build;${WORK_DIR}/consumer")
  execute_process(COMMAND ${step} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed: ${step}\n${out}\n${err}")
  endif()
endforeach()
execute_process(COMMAND ${WORK_DIR}/consumer/app RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "pair 0: converged, distance 0.140000")
  message(FATAL_ERROR "the installed example printed: ${out} (exit ${rc})")
endif()
