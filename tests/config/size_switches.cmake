# The #error range checks of the build-time size switches (include/*.h):
# run as ctest unit.size_switches, `cmake -DCC=... -DFLAGS=... -DINCLUDE=...
# -DSRC=... -P size_switches.cmake`. Each case compiles SRC (syntax only,
# the project's warnings) with its definitions: a good case must build, a
# bad one must fail with the message of its switch's #error (the compiler
# may report what follows from the bad value too). About 0.1 s a case.
separate_arguments(flags UNIX_COMMAND "${FLAGS}")

# "definitions|expected #error text (empty: must build)"
set(cases
  "|"
  "-DCO_TPDO_MAX=1u -DCO_SDO_BUF=4u -DCO_EMCY_HIST_MAX=0u -DCO_EMCY_ACTIVE_MAX=1u -DCO_INCL_CIRCULAR=0|"
  "-DCO_TPDO_MAX=512u -DCO_SDO_BUF=889u -DCO_EMCY_HIST_MAX=254u -DCO_EMCY_ACTIVE_MAX=255u -DCO_INCL_CIRCULAR=1|"
  "-DCO_TPDO_MAX=0|CO_TPDO_MAX must be 1..512"
  "-DCO_TPDO_MAX=513u|CO_TPDO_MAX must be 1..512"
  "-DCO_TPDO_MAX=two|CO_TPDO_MAX must be 1..512"
  "-DCO_SDO_BUF=3u|CO_SDO_BUF must be 4..889"
  "-DCO_SDO_BUF=890|CO_SDO_BUF must be 4..889"
  "-DCO_EMCY_ACTIVE_MAX=0u|CO_EMCY_ACTIVE_MAX must be 1..255"
  "-DCO_EMCY_ACTIVE_MAX=256|CO_EMCY_ACTIVE_MAX must be 1..255"
  "-DCO_EMCY_HIST_MAX=255u|CO_EMCY_HIST_MAX must be 0..254"
  "-DCO_EMCY_HIST_MAX=-1|CO_EMCY_HIST_MAX must be 0..254"
  "-DCO_INCL_CIRCULAR=2|CO_INCL_CIRCULAR must be 0 or 1"
)
foreach(c ${cases})
  string(FIND "${c}" "|" bar)
  string(SUBSTRING "${c}" 0 ${bar} defs)
  math(EXPR bar "${bar} + 1")
  string(SUBSTRING "${c}" ${bar} -1 expect)
  separate_arguments(defs UNIX_COMMAND "${defs}")
  execute_process(COMMAND ${CC} ${flags} ${INCLUDE} ${defs} -fsyntax-only ${SRC}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(expect STREQUAL "")
    if(NOT rc EQUAL 0)
      message(SEND_ERROR "'${defs}' must build, but:\n${out}")
    else()
      message(STATUS "ok   '${defs}' builds")
    endif()
  elseif(rc EQUAL 0)
    message(SEND_ERROR "'${defs}' must fail with \"${expect}\", but it builds")
  else()
    string(FIND "${out}" "#error \"${expect}" at)
    string(FIND "${out}" "error: ${expect}" at2)
    if(at EQUAL -1 AND at2 EQUAL -1)
      message(SEND_ERROR "'${defs}' must fail with \"${expect}\", but:\n${out}")
    else()
      message(STATUS "ok   '${defs}' fails: ${expect}")
    endif()
  endif()
endforeach()
