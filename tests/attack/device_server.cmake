# Device and server part of the attack suite: planted key files against every binary that
# takes a key, and a flood of forged statuses, 1 MiB datagrams and forged models at the
# device (genuine statuses and models still get through).
snapthread_add_test(device_key_refusal_test
  SOURCES device_key_refusal_test.cc
  LIBS snapthread::test_support
  LABELS attack
  TIMEOUT 300)
foreach(binary snapthread-server snapthread-device snapthread-viewer snapthread-web
               snapthread-scene-shape snapthread-ctl snapthread-keygen)
  if(TARGET ${binary})
    add_dependencies(device_key_refusal_test ${binary})
  endif()
endforeach()
snapthread_add_test(device_flood_test
  SOURCES device_flood_test.cc
  LIBS snapthread::messages snapthread::auth snapthread::test_support
  LABELS attack
  SERIAL
  TIMEOUT 120)
# The fake server of the device's process tests (header-only).
target_include_directories(device_flood_test PRIVATE ${PROJECT_SOURCE_DIR}/tests/service)
add_dependencies(device_flood_test snapthread-device)
