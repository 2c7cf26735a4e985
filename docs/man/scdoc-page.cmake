# Builds one man page: cmake -DSCDOC=... -DGZIP=... -DSOURCE=NAME.N.scd -DPAGE=OUT/NAME.N
# -DVERSION=X.Y.Z -P scdoc-page.cmake. Writes PAGE (roff, by scdoc) and PAGE.gz (gzip -9n: no
# name or time stamp, as Debian policy wants). `@VERSION@` in the source becomes VERSION, and a
# preamble without a footer ("atelierd.toml(5)") gets "atelier VERSION" as its left footer, so
# every page says which release it describes.
cmake_minimum_required(VERSION 3.25)  # policies: "@VERSION@" is a literal, not a variable
file(READ ${SOURCE} text)
string(REPLACE "@VERSION@" "${VERSION}" text "${text}")
string(REGEX REPLACE "^([^ \n]+\\([0-9]\\))[ \t]*\n" "\\1 \"atelier ${VERSION}\"\n" text "${text}")
file(WRITE ${PAGE}.scd "${text}")
execute_process(COMMAND ${SCDOC} INPUT_FILE ${PAGE}.scd OUTPUT_FILE ${PAGE}.tmp
                ERROR_VARIABLE error RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  file(REMOVE ${PAGE}.tmp)
  message(FATAL_ERROR "${SOURCE}: scdoc: ${error}")
endif()
file(RENAME ${PAGE}.tmp ${PAGE})
execute_process(COMMAND ${GZIP} -9n -c ${PAGE} OUTPUT_FILE ${PAGE}.gz RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${PAGE}: gzip failed")
endif()
