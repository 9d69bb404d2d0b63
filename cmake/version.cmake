# Writes the version header with the current git hash at every build (not only at configure
# time), so outputs never carry a stale hash. configure_file leaves the file untouched when the
# content is unchanged, so nothing is recompiled unless the hash changed.
execute_process(COMMAND git describe --always --dirty --abbrev=12
                WORKING_DIRECTORY ${SRC_DIR}
                OUTPUT_VARIABLE NIPDEM_GIT_HASH OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT NIPDEM_GIT_HASH)
  set(NIPDEM_GIT_HASH "unknown")
endif()
set(PROJECT_VERSION ${VERSION})
configure_file(${IN} ${OUT} @ONLY)
