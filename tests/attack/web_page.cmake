# snapthread-web as a target (docs/security.md, "The edges"): its door (token, cookie,
# Host, Origin, --max-pages, the security headers), a hostile log replayed into headless
# Chromium, and a keyless flood of forged device ids. Real binaries over loopback.
if(SNAPTHREAD_BUILD_WEB)
  snapthread_add_test(web_access_test
    SOURCES web_access_test.cc
    LIBS snapthread::test_support
    LABELS "attack;web"
    TIMEOUT 120)
  add_dependencies(web_access_test snapthread-web)

  # The browser and the live session take both cores: each runs alone (RUN_SERIAL), as
  # tests/web's browser tests do.
  add_executable(web_injection_test web_injection_test.cc)
  target_link_libraries(web_injection_test PRIVATE snapthread::test_support snapthread::auth snapthread::lcmtypes
    PkgConfig::LCM GTest::gtest GTest::gtest_main snapthread::warnings)
  target_include_directories(web_injection_test PRIVATE ${PROJECT_SOURCE_DIR}/tests/support)
  set_target_properties(web_injection_test PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
  target_compile_definitions(web_injection_test PRIVATE
    SNAPTHREAD_WEB_NODE_MODULES="${SNAPTHREAD_WEB_NODE_MODULES}"
    SNAPTHREAD_WEB_INJECTION_CHECK="${CMAKE_CURRENT_SOURCE_DIR}/web_injection_check.mjs"
    SNAPTHREAD_NODE="${SNAPTHREAD_NODE}")
  add_dependencies(web_injection_test snapthread-web)
  add_test(NAME web_injection_test COMMAND web_injection_test)

  add_executable(web_flood_test web_flood_test.cc)
  target_link_libraries(web_flood_test PRIVATE snapthread::test_support snapthread::messages
    snapthread::lcmtypes PkgConfig::LCM GTest::gtest GTest::gtest_main snapthread::warnings)
  target_include_directories(web_flood_test PRIVATE ${PROJECT_SOURCE_DIR}/tests/support)
  set_target_properties(web_flood_test PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
  add_dependencies(web_flood_test snapthread-web snapthread-server snapthread-device)
  add_test(NAME web_flood_test COMMAND web_flood_test)

  set_tests_properties(web_injection_test web_flood_test PROPERTIES
    LABELS "attack;web;process" TIMEOUT 300 RUN_SERIAL TRUE)
endif()
