# Turns one OpenCL C file into a header holding its source as a raw string literal.
# Called by CMakeLists.txt with -DINPUT=file.cl -DOUTPUT=file_cl.h -DNAME=name.
file(READ ${INPUT} source)
string(FIND "${source}" ")meshquilt_cl\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${INPUT} contains the raw-string delimiter")
endif()
file(WRITE ${OUTPUT}.tmp
  "// Generated from ${INPUT}; do not edit.\n#pragma once\n"
  "namespace mq::kernels {\ninline constexpr const char* ${NAME}_source = R\"meshquilt_cl(${source})meshquilt_cl\";\n}\n")
file(RENAME ${OUTPUT}.tmp ${OUTPUT})
