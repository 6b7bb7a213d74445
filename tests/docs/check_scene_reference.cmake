# Regenerates the scene reference with `pneufem scene --reference` and compares it with the
# committed docs/scene_reference.md (ctest scene_reference_is_current).
execute_process(COMMAND ${EXE} scene --reference OUTPUT_FILE ${OUT} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pneufem scene --reference failed (exit ${rc})")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT} ${DOC} RESULT_VARIABLE differ)
if(NOT differ EQUAL 0)
  message(FATAL_ERROR "docs/scene_reference.md is out of date: the default scene or the effect registry changed. "
                      "Regenerate it: build/app/pneufem scene --reference > docs/scene_reference.md "
                      "(the new text is in ${OUT})")
endif()
