# What `cmake --install build --prefix P` installs (component "cli"):
#   P/bin/plenoptic
#   P/share/bash-completion/completions/plenoptic   `plenoptic completion bash`
#   P/share/man/man1/plenoptic.1                    `plenoptic manpage`
#   P/share/doc/plenoptic/                          README.md, the licence and other notices
#                                                   present at the top of the tree, and docs/
# The completion script and the man page are generated at build time by the program just
# built, from its own command-line definition (src/app/cli_support.h), so they always match
# it. The Python module is not installed here: it is installed as a Python package by its
# own packaging, which may add its rules under another component.
include(GNUInstallDirs)

set(PLENOPTIC_COMPLETION "${CMAKE_BINARY_DIR}/share/bash-completion/completions/plenoptic")
set(PLENOPTIC_MANPAGE "${CMAKE_BINARY_DIR}/share/man/man1/plenoptic.1")
add_custom_command(OUTPUT "${PLENOPTIC_COMPLETION}"
  COMMAND "${CMAKE_COMMAND}" -E make_directory "${CMAKE_BINARY_DIR}/share/bash-completion/completions"
  COMMAND plenoptic completion bash --output "${PLENOPTIC_COMPLETION}"
  DEPENDS plenoptic
  COMMENT "Generating the bash completion of plenoptic" VERBATIM)
add_custom_command(OUTPUT "${PLENOPTIC_MANPAGE}"
  COMMAND "${CMAKE_COMMAND}" -E make_directory "${CMAKE_BINARY_DIR}/share/man/man1"
  COMMAND plenoptic manpage --output "${PLENOPTIC_MANPAGE}"
  DEPENDS plenoptic
  COMMENT "Generating the man page of plenoptic" VERBATIM)
add_custom_target(plenoptic_shell_files ALL DEPENDS "${PLENOPTIC_COMPLETION}" "${PLENOPTIC_MANPAGE}")

install(TARGETS plenoptic RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}" COMPONENT cli)
install(FILES "${PLENOPTIC_COMPLETION}" DESTINATION "${CMAKE_INSTALL_DATADIR}/bash-completion/completions" COMPONENT cli)
install(FILES "${PLENOPTIC_MANPAGE}" DESTINATION "${CMAKE_INSTALL_MANDIR}/man1" COMPONENT cli)
install(FILES "${PROJECT_SOURCE_DIR}/README.md" DESTINATION "${CMAKE_INSTALL_DOCDIR}" COMPONENT cli)
# Whichever of these the tree holds when installing (OPTIONAL: checked then, not at configure).
foreach(notice LICENSE LICENSE.md LICENSE.txt COPYING NOTICE NOTICE.md CHANGELOG.md CHANGELOG CITATION.cff
        THIRD_PARTY.md)
  install(FILES "${PROJECT_SOURCE_DIR}/${notice}" DESTINATION "${CMAKE_INSTALL_DOCDIR}" COMPONENT cli OPTIONAL)
endforeach()
install(DIRECTORY "${PROJECT_SOURCE_DIR}/docs/" DESTINATION "${CMAKE_INSTALL_DOCDIR}/docs" COMPONENT cli)

# install_test installs into a fresh prefix under the build tree and checks the result
# (cmake/install_test.cmake); version_test runs cmake/version.cmake outside git and in a
# clean, a modified and a tagged checkout (cmake/version_test.cmake).
if(BUILD_TESTING)
  add_test(NAME version_test
    COMMAND "${CMAKE_COMMAND}" -DSCRATCH=${CMAKE_BINARY_DIR}/version_test_scratch
            -DSCRIPT=${PROJECT_SOURCE_DIR}/cmake/version.cmake -P "${PROJECT_SOURCE_DIR}/cmake/version_test.cmake")
  add_test(NAME install_test
    COMMAND "${CMAKE_COMMAND}" -DBUILD_DIR=${CMAKE_BINARY_DIR} -DPREFIX=${CMAKE_BINARY_DIR}/install_test_prefix
            -DPROJECT_VERSION=${PROJECT_VERSION} -P "${PROJECT_SOURCE_DIR}/cmake/install_test.cmake")
endif()
