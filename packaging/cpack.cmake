# Debian packages made by the build: `cmake --build build --target package` (or `cpack` in a
# built build folder; tools/make-deb configures a build of the programs only and runs it) writes
#   atelier_VERSION_amd64.deb            component "atelier": the daemon, atelierctl,
#                                        atelier-convert, the unit, sysusers.d, tmpfiles.d,
#                                        udev rules, /etc/atelier/atelierd.toml (a conffile),
#                                        man pages, bash completion
#   atelier-emulators_VERSION_amd64.deb  component "emulators": atelier-knit-emu and
#                                        atelier-laser-emu
# COMPONENTS for install() rules: `atelier` (the default, CMAKE_INSTALL_DEFAULT_COMPONENT_NAME
# in the top-level CMakeLists.txt, so a rule without COMPONENT lands in the daemon's package)
# and `emulators`. The emulators are a package of their own: a workshop with real machines
# does not want two fake machines in its PATH, and the boot test (tests/boot/) installs both.
# Depends come from the programs' shared libraries (dpkg-shlibdeps) plus what the package
# runs or reads: systemd (sysusers, tmpfiles, the unit), init-system-helpers
# (deb-systemd-helper/-invoke in the maintainer scripts), hershey-fonts-data (engraved text).

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME atelier)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "atelier")
set(CPACK_PACKAGE_CONTACT "atelier maintainers <atelier@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "workshop fabrication daemon: hot folder, job queue, knitting machine and laser")
set(CPACK_PACKAGE_DESCRIPTION
  "atelierd turns images dropped into a hot folder into fabrication data (knitting, lace,\n embroidery, parquetry, sketch and laser-cut jobs) and drives the machines on the box:\n Brother knitting machines through AYAB and GRBL 1.1 laser cutters.")
# A package installs into /usr, from any build (whatever its CMAKE_INSTALL_PREFIX): the install
# scripts of systemd/ and config/ work out the unit's ExecStart and --config and the absolute
# destinations (/etc, /lib/systemd/system) from the install-time prefix, and those need a
# DESTDIR install.
set(CPACK_INSTALL_PREFIX /usr)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_SET_DESTDIR ON)

set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL atelier emulators)
set(CPACK_COMPONENT_ATELIER_DESCRIPTION "${CPACK_PACKAGE_DESCRIPTION}")
set(CPACK_COMPONENT_EMULATORS_DESCRIPTION
  "atelier-knit-emu (the AYAB firmware on a Brother KH-9xx/KH-270) and atelier-laser-emu\n (a GRBL 1.1h laser controller), each on a pseudo-terminal, for trying atelierd without\n the machines.")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS OFF)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
# Stripped programs (RelWithDebInfo builds carry 150 MB of debug info in atelierd alone).
set(CPACK_STRIP_FILES ON)

set(CPACK_DEBIAN_ATELIER_PACKAGE_NAME atelier)
set(CPACK_DEBIAN_ATELIER_PACKAGE_DEPENDS "systemd, init-system-helpers (>= 1.52), hershey-fonts-data")
set(CPACK_DEBIAN_ATELIER_PACKAGE_RECOMMENDS "udev")
set(CPACK_DEBIAN_EMULATORS_PACKAGE_NAME atelier-emulators)
set(CPACK_DEBIAN_EMULATORS_PACKAGE_SECTION misc)

# /etc/atelier/atelierd.toml is a conffile: an upgrade keeps the workshop's edits (dpkg asks).
set(CPACK_DEBIAN_ATELIER_PACKAGE_CONTROL_EXTRA
  ${PROJECT_SOURCE_DIR}/packaging/debian/conffiles
  ${PROJECT_SOURCE_DIR}/packaging/debian/postinst
  ${PROJECT_SOURCE_DIR}/packaging/debian/prerm
  ${PROJECT_SOURCE_DIR}/packaging/debian/postrm)

include(CPack)
