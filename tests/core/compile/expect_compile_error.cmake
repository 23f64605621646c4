# ctest -P script: SOURCE compiles with the project's flags (FLAGS, a ;-list), and fails to compile
# with -D${DEFINE}, with an error that mentions EXPECT (the type the wrong read produces). The
# first compile shows that the second fails for the type alone.
separate_arguments(flags NATIVE_COMMAND "${FLAGS}")
execute_process(COMMAND ${COMPILER} ${flags} -fsyntax-only ${SOURCE}
                RESULT_VARIABLE good_result ERROR_VARIABLE good_error)
if(NOT good_result EQUAL 0)
  message(FATAL_ERROR "${SOURCE} does not compile as it is:\n${good_error}")
endif()
execute_process(COMMAND ${COMPILER} ${flags} -D${DEFINE} -fsyntax-only ${SOURCE}
                RESULT_VARIABLE bad_result ERROR_VARIABLE bad_error)
if(bad_result EQUAL 0)
  message(FATAL_ERROR "${SOURCE} compiles with -D${DEFINE}: the wrong type was accepted")
endif()
string(FIND "${bad_error}" "${EXPECT}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "${SOURCE} with -D${DEFINE} failed, but not over ${EXPECT}:\n${bad_error}")
endif()
message(STATUS "-D${DEFINE} is rejected: ${EXPECT}")
