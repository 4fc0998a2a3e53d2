# Runs at install time (install(CODE) in daemon/mpmd/CMakeLists.txt), so the
# units name the prefix actually installed to (`cmake --install --prefix P`
# included). Puts in place:
#   <prefix>/lib/systemd/system/mpmd.service, mpmd@.service
#   <sysconfdir>/mpm/mpmd.yaml, wood-berry.yaml, cyclonedds-*.xml  (only where
#       absent: a reinstall never overwrites an operator's configuration)
# with sysconfdir = /etc for prefix /usr, else <prefix>/etc (GNUInstallDirs).
# Expects MPM_SOURCE_DIR.
set(_prefix "${CMAKE_INSTALL_PREFIX}")
if(_prefix STREQUAL "/usr")
  set(_sysconf "/etc")
else()
  set(_sysconf "${_prefix}/etc")
endif()
set(MPM_BIN_DIR "${_prefix}/bin")
set(MPM_CONFIG_DIR "${_sysconf}/mpm")
set(MPM_DOC_DIR "${_prefix}/share/doc/mpm")
file(READ "${MPM_SOURCE_DIR}/deploy/systemd/hardening.conf" MPM_HARDENING)

set(_units "$ENV{DESTDIR}${_prefix}/lib/systemd/system")
foreach(unit mpmd.service mpmd@.service)
  message(STATUS "Installing: ${_units}/${unit}")
  configure_file("${MPM_SOURCE_DIR}/deploy/systemd/${unit}.in" "${_units}/${unit}" @ONLY)
endforeach()

set(_etc "$ENV{DESTDIR}${MPM_CONFIG_DIR}")
foreach(pair
    "deploy/mpmd.yaml;mpmd.yaml"
    "config/wood-berry.yaml;wood-berry.yaml"
    "deploy/dds/cyclonedds-loopback.xml;cyclonedds-loopback.xml"
    "deploy/dds/cyclonedds-plant-network.xml;cyclonedds-plant-network.xml")
  list(GET pair 0 _from)
  list(GET pair 1 _to)
  if(EXISTS "${_etc}/${_to}")
    message(STATUS "Kept (exists): ${_etc}/${_to}")
  else()
    # file(INSTALL) puts DESTDIR in front itself: name the final directory.
    file(INSTALL "${MPM_SOURCE_DIR}/${_from}" DESTINATION "${MPM_CONFIG_DIR}")
  endif()
endforeach()
