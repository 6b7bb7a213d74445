# Generates a header holding a text file as a raw string literal (the built-in default scene).
file(READ ${INPUT} CONTENT)
file(WRITE ${OUTPUT} "#pragma once\n// Generated from ${INPUT_NAME}; do not edit.\ninline constexpr const char* ${SYMBOL} = R\"pneufem_scene(${CONTENT})pneufem_scene\";\n")
