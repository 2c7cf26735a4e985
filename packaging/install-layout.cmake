# Where atelier's files go for an install prefix, worked out when installing (included by the
# install scripts of systemd/ and config/, with ATELIER_PREFIX set to the install-time
# CMAKE_INSTALL_PREFIX). So `cmake --install build --prefix /usr`, a build configured with
# -DCMAKE_INSTALL_PREFIX=/usr, and CPack (which installs any build with prefix /usr) all give
# the same layout, and the installed unit names the files the install put in place.
# For prefix /usr, as Debian bookworm lays it out:
#   ATELIER_BINDIR          /usr/bin                  (<prefix>/<bindir>)
#   ATELIER_SYSCONFDIR      /etc                      (GNUInstallDirs' rule: <prefix>/etc otherwise,
#                                                      an absolute CMAKE_INSTALL_SYSCONFDIR as given)
#   ATELIER_SYSTEMD_UNITDIR /lib/systemd/system       (<prefix>/lib/systemd/system)
#   ATELIER_SYSTEMD_GENERATORDIR /lib/systemd/system-generators (<prefix>/lib/systemd/system-generators)
#   ATELIER_UDEV_RULESDIR   /lib/udev/rules.d         (<prefix>/lib/udev/rules.d)
#   ATELIER_SYSUSERSDIR     /usr/lib/sysusers.d       (<prefix>/lib/sysusers.d)
#   ATELIER_TMPFILESDIR     /usr/lib/tmpfiles.d       (<prefix>/lib/tmpfiles.d)
# Inputs: ATELIER_PREFIX, ATELIER_BINDIR_REL and ATELIER_SYSCONFDIR_REL (the configured
# CMAKE_INSTALL_BINDIR and CMAKE_INSTALL_SYSCONFDIR).
string(REGEX REPLACE "/+$" "" _prefix "${ATELIER_PREFIX}")
if(IS_ABSOLUTE "${ATELIER_BINDIR_REL}")
  set(ATELIER_BINDIR "${ATELIER_BINDIR_REL}")
else()
  set(ATELIER_BINDIR "${_prefix}/${ATELIER_BINDIR_REL}")
endif()
if(IS_ABSOLUTE "${ATELIER_SYSCONFDIR_REL}")
  set(ATELIER_SYSCONFDIR "${ATELIER_SYSCONFDIR_REL}")
elseif(_prefix STREQUAL "/usr" OR _prefix STREQUAL "")
  set(ATELIER_SYSCONFDIR "/etc")
else()
  set(ATELIER_SYSCONFDIR "${_prefix}/${ATELIER_SYSCONFDIR_REL}")
endif()
if(_prefix STREQUAL "/usr" OR _prefix STREQUAL "")
  set(ATELIER_SYSTEMD_UNITDIR "/lib/systemd/system")
  set(ATELIER_SYSTEMD_GENERATORDIR "/lib/systemd/system-generators")
  set(ATELIER_UDEV_RULESDIR "/lib/udev/rules.d")
  set(ATELIER_SYSUSERSDIR "/usr/lib/sysusers.d")
  set(ATELIER_TMPFILESDIR "/usr/lib/tmpfiles.d")
else()
  set(ATELIER_SYSTEMD_UNITDIR "${_prefix}/lib/systemd/system")
  set(ATELIER_SYSTEMD_GENERATORDIR "${_prefix}/lib/systemd/system-generators")
  set(ATELIER_UDEV_RULESDIR "${_prefix}/lib/udev/rules.d")
  set(ATELIER_SYSUSERSDIR "${_prefix}/lib/sysusers.d")
  set(ATELIER_TMPFILESDIR "${_prefix}/lib/tmpfiles.d")
endif()
