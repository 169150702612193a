# Run by `cmake --install` (packaging/CMakeLists.txt), when the prefix installed to is known
# (`cmake --install --prefix P` may differ from the configured one): the systemd unit, its
# ExecStart and --config naming this prefix's daemon and config, and the default config, in
# /etc for the /usr prefix (a distribution's) and in P/etc for any other; an existing config is
# kept.
# The Python package of the LCM types goes where Debian's python3 looks: lib/python3/dist-packages
# for /usr, lib/python3.X/dist-packages for any other prefix (/usr/local's is on its path).
# In: HAPTICSIM_UNIT (the shipped unit), HAPTICSIM_BINDIR (relative), HAPTICSIM_DEFAULT_CONFIG,
# HAPTICSIM_SYSUSERS, HAPTICSIM_PYTHON_PACKAGE (the built package's directory),
# HAPTICSIM_PYTHON_VERSION ("3.11").
if(CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  set(sysconfdir "/etc")
else()
  set(sysconfdir "${CMAKE_INSTALL_PREFIX}/etc")
endif()
set(daemon "${CMAKE_INSTALL_PREFIX}/${HAPTICSIM_BINDIR}/hapticsimd")
file(READ "${HAPTICSIM_UNIT}" unit)
string(REPLACE "/usr/local/bin/hapticsimd" "${daemon}" unit "${unit}")
string(REPLACE "/etc/hapticsim/" "${sysconfdir}/hapticsim/" unit "${unit}")
get_filename_component(staging "${HAPTICSIM_DEFAULT_CONFIG}" DIRECTORY)
file(WRITE "${staging}/staged/hapticsimd.service" "${unit}")
file(INSTALL "${staging}/staged/hapticsimd.service"
     DESTINATION "${CMAKE_INSTALL_PREFIX}/lib/systemd/system")
file(INSTALL "${HAPTICSIM_SYSUSERS}" DESTINATION "${CMAKE_INSTALL_PREFIX}/lib/sysusers.d"
     RENAME hapticsim.conf)
# The config is the administrator's once it is there: never overwritten (the defaults go beside
# it, as hapticsimd.toml.default, for comparing).
if(EXISTS "$ENV{DESTDIR}${sysconfdir}/hapticsim/hapticsimd.toml")
  message(STATUS "Kept: $ENV{DESTDIR}${sysconfdir}/hapticsim/hapticsimd.toml (an install never "
                 "overwrites it; the defaults are in hapticsimd.toml.default beside it)")
  file(INSTALL "${HAPTICSIM_DEFAULT_CONFIG}" DESTINATION "${sysconfdir}/hapticsim"
       RENAME hapticsimd.toml.default)
else()
  file(INSTALL "${HAPTICSIM_DEFAULT_CONFIG}" DESTINATION "${sysconfdir}/hapticsim")
endif()

if(CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  set(python_dir "${CMAKE_INSTALL_PREFIX}/lib/python3/dist-packages")
else()
  set(python_dir "${CMAKE_INSTALL_PREFIX}/lib/python${HAPTICSIM_PYTHON_VERSION}/dist-packages")
endif()
file(INSTALL "${HAPTICSIM_PYTHON_PACKAGE}" DESTINATION "${python_dir}"
     PATTERN "__pycache__" EXCLUDE)
