# ctest helper: runs part21-fuzz-replay on the Part 21 files of the sample
# corpus (*.stp, *.p21, *.stpnc, and the extension-less files of
# jucsr__sanssouci/), which are read in place and never copied.
#   cmake -DREPLAY=<part21-fuzz-replay> -DCORPUS=<dir> -P ReplayCorpus.cmake
file(GLOB_RECURSE _inputs LIST_DIRECTORIES false
  ${CORPUS}/*.stp ${CORPUS}/*.p21 ${CORPUS}/*.stpnc)
file(GLOB _plain LIST_DIRECTORIES false ${CORPUS}/jucsr__sanssouci/*)
foreach(_f IN LISTS _plain)
  get_filename_component(_name "${_f}" NAME)
  if(NOT _name MATCHES "\\.")
    list(APPEND _inputs "${_f}")
  endif()
endforeach()
list(REMOVE_DUPLICATES _inputs)
list(SORT _inputs)
list(LENGTH _inputs _n)
if(_n EQUAL 0)
  message(FATAL_ERROR "no Part 21 files found in ${CORPUS}")
endif()
execute_process(COMMAND ${REPLAY} ${_inputs} RESULT_VARIABLE _rc)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "part21-fuzz-replay failed on the corpus (${_rc})")
endif()
