# Read by cpack (CPACK_PROJECT_CONFIG_FILE) before it packages: a .deb installs into /usr, and
# the unit and the config path in it are fixed when the build is configured, so only a build
# configured with -DCMAKE_INSTALL_PREFIX=/usr can make one.
if(CPACK_GENERATOR STREQUAL "DEB" AND NOT CPACK_PACKAGING_INSTALL_PREFIX STREQUAL "/usr")
  message(FATAL_ERROR
    "atelier: a Debian package needs a build configured with -DCMAKE_INSTALL_PREFIX=/usr "
    "(this one has ${CPACK_PACKAGING_INSTALL_PREFIX}); tools/make-deb configures one and packages it")
endif()
