# A hostile log against snapthread-report: the real snapthread-logger records a genuine
# session while a keyless sender publishes on channels named to inject shell and gnuplot
# commands (LAB1_';system "id>pwned"#_FORCE_MODEL and variants); the report must run none of
# them, still draw the genuine session, and show the names escaped (the viewer's live
# rates too).
snapthread_add_test(report_injection_test
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/report_injection_test.cc
  LIBS snapthread::lcmtypes snapthread::messages snapthread::png_image snapthread::test_support
       PkgConfig::LCM
  LABELS attack
  TIMEOUT 300)
add_dependencies(report_injection_test snapthread-report snapthread-logger snapthread-viewer)
