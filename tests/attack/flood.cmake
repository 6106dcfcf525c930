# Forged flood (docs/security.md, "Flooding"): a genuine server + device under a keyless
# flood of forged messages on every session channel. The forger (tools/bench/
# flood_forger.cc) is the one snapthread-bench's flood chart uses.
snapthread_add_test(flood_attack_test
  SOURCES flood_test.cc ${PROJECT_SOURCE_DIR}/tools/bench/flood_forger.cc
  LIBS snapthread::messages snapthread::auth snapthread::test_support
  LABELS attack
  SERIAL
  TIMEOUT 240)
target_include_directories(flood_attack_test PRIVATE ${PROJECT_SOURCE_DIR}/tools/bench)
add_dependencies(flood_attack_test snapthread-server snapthread-device)
