# Writes the version header with the current git hash at every build (not only at configure
# time), so outputs never carry a stale hash. configure_file leaves the file untouched when the
# content is unchanged, so nothing is recompiled unless the hash changed.
# "-dirty" marks a build from changed sources; files under docs/ (where studies write their results
# into the tree while they run) do not make a build dirty.
execute_process(COMMAND git describe --always --abbrev=12
                WORKING_DIRECTORY ${SRC_DIR}
                OUTPUT_VARIABLE NIPDEM_GIT_HASH OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT NIPDEM_GIT_HASH)
  set(NIPDEM_GIT_HASH "unknown")
else()
  execute_process(COMMAND git status --porcelain -- . ":(exclude)docs"
                  WORKING_DIRECTORY ${SRC_DIR}
                  OUTPUT_VARIABLE NIPDEM_CHANGED OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(NIPDEM_CHANGED)
    string(APPEND NIPDEM_GIT_HASH "-dirty")
  endif()
endif()
set(PROJECT_VERSION ${VERSION})
configure_file(${IN} ${OUT} @ONLY)
