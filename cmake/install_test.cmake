# ctest install_test: `cmake --install BUILD_DIR --prefix PREFIX` into a fresh PREFIX, then
# checks that every file is there and that the installed program, its completion script and
# its man page work. cmake -DBUILD_DIR=... -DPREFIX=... -DPROJECT_VERSION=... -P install_test.cmake
function(fail)
  string(JOIN "" text ${ARGN})
  message(FATAL_ERROR "install_test: ${text}")
endfunction()

file(REMOVE_RECURSE "${PREFIX}")
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${PREFIX}"
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  fail("cmake --install failed (${status}):\n${out}${err}")
endif()

set(program "${PREFIX}/bin/plenoptic")
set(completion "${PREFIX}/share/bash-completion/completions/plenoptic")
set(manpage "${PREFIX}/share/man/man1/plenoptic.1")
foreach(file "${program}" "${completion}" "${manpage}" "${PREFIX}/share/doc/plenoptic/README.md")
  if(NOT EXISTS "${file}")
    fail("${file} was not installed")
  endif()
endforeach()
if(NOT IS_DIRECTORY "${PREFIX}/share/doc/plenoptic/docs")
  fail("docs/ was not installed in share/doc/plenoptic")
endif()

# The installed program runs (no build-tree paths needed) and says which version it is.
execute_process(COMMAND "${program}" --version RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REPLACE "." "\\." version_pattern "${PROJECT_VERSION}")
if(NOT status EQUAL 0 OR NOT out MATCHES "^plenoptic ${version_pattern}( \\([A-Za-z0-9._+-]+\\))?\n$" OR NOT err STREQUAL "")
  fail("'plenoptic --version' gave status ${status}, output '${out}', errors '${err}'")
endif()
execute_process(COMMAND "${program}" --help RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT status EQUAL 0 OR NOT out MATCHES "trace" OR NOT out MATCHES "bake" OR NOT err STREQUAL "")
  fail("'plenoptic --help' gave status ${status}, output '${out}', errors '${err}'")
endif()

# The completion script, sourced by bash, completes a command name and a flag.
find_program(BASH bash)
if(BASH)
  execute_process(COMMAND "${BASH}" --norc --noprofile -c
    "source '${completion}' && COMP_WORDS=(plenoptic tra) COMP_CWORD=1 && _plenoptic && echo \"\${COMPREPLY[*]}\" && COMP_WORDS=(plenoptic trace --sp) COMP_CWORD=2 && _plenoptic && echo \"\${COMPREPLY[*]}\""
    RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0 OR NOT out STREQUAL "trace\n--spp\n" OR NOT err STREQUAL "")
    fail("the installed completion gave status ${status}, output '${out}', errors '${err}'")
  endif()
endif()

# The man page is well-formed roff: groff renders it without a warning.
file(READ "${manpage}" man)
if(NOT man MATCHES "\n\\.TH PLENOPTIC 1 ")
  fail("${manpage} has no .TH PLENOPTIC 1 header")
endif()
find_program(GROFF groff)
if(GROFF)
  execute_process(COMMAND "${GROFF}" -man -Tutf8 -ww -z "${manpage}" RESULT_VARIABLE status ERROR_VARIABLE err)
  if(NOT status EQUAL 0 OR NOT err STREQUAL "")
    fail("groff warns about ${manpage}:\n${err}")
  endif()
endif()
file(REMOVE_RECURSE "${PREFIX}")
