# Install rules and the Debian package (CPack), included at the end of the top CMakeLists.txt.
#
#   cmake --install build [--prefix DIR]      # default prefix /usr/local
#   cd build && cpack -G DEB                  # pneufem_<version>_<arch>.deb, installs under /usr
#
# What goes where (GNUInstallDirs, relative to the prefix):
#   bin/pneufem                                   the executable (its default scene is built in)
#   share/pneufem/examples/*.toml                 the example scenes (scenes/examples/)
#   share/pneufem/paraview/open_run.py            the ParaView state of a run directory
#   share/doc/pneufem/                            README.md, BENCHMARKS.md, docs/ (manuals, figures)
#   ${PNEUFEM_INSTALL_PYTHONDIR}                  the Python module: python/CMakeLists.txt installs it
#                                                 there itself (the hook: the variable, set in the top
#                                                 CMakeLists.txt before the subdirectories, and
#                                                 PNEUFEM_DEB_DEPENDS below for what it needs at run time)
# The package's library dependencies are found by dpkg-shlibdeps from the binary (libtbb12,
# libvtk9.1, libopenvdb10.0, libcholmod3, ...); PNEUFEM_DEB_DEPENDS adds those it cannot see.
# What the package holds that a build must make first: `./scripts/build.sh packaged` builds them
# (the main job builds the executable alone, and cpack does not build).
add_custom_target(packaged)
add_dependencies(packaged pneufem)
if(TARGET pneufem_python)
  add_dependencies(packaged pneufem_python)
endif()
install(TARGETS pneufem RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenes/examples/ DESTINATION ${CMAKE_INSTALL_DATADIR}/pneufem/examples
        FILES_MATCHING PATTERN "*.toml")
install(FILES ${PROJECT_SOURCE_DIR}/viz/paraview/open_run.py DESTINATION ${CMAKE_INSTALL_DATADIR}/pneufem/paraview)
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/BENCHMARKS.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs)

set(CPACK_PACKAGE_NAME pneufem)
set(CPACK_PACKAGE_VENDOR "pneufem")
set(CPACK_PACKAGE_CONTACT "pneufem maintainers <pneufem@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "${PNEUFEM_DEB_DEPENDS}")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "slurm-client, paraview")  # sweep --scheduler slurm; viewing runs
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "FEM simulator of pneumatic soft bending actuators (pneu-nets): simulate, compare with\n recordings, diagnose the missing physical effect, sweep (locally or on SLURM).")
include(CPack)
