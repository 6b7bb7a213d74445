# Writes OUT (a header defining PNEUFEM_GIT, `git describe --always --dirty --tags` of SOURCE_DIR)
# at every build, but touches it only when the text changes, so an unchanged tree recompiles
# nothing. Run by the pneufem_git_version target (app/CMakeLists.txt): a version taken at configure
# time goes stale after the next commit and every output records it.
execute_process(COMMAND git describe --always --dirty --tags
                WORKING_DIRECTORY ${SOURCE_DIR}
                OUTPUT_VARIABLE git OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT git)
  set(git "unknown")
endif()
set(text "#pragma once\n#define PNEUFEM_GIT \"${git}\"\n")
if(EXISTS ${OUT})
  file(READ ${OUT} old)
endif()
if(NOT "${old}" STREQUAL "${text}")
  file(WRITE ${OUT} "${text}")
endif()
