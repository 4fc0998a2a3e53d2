# The wire decoders' fuzz targets (issue 12), included by
# tests/fuzz/CMakeLists.txt, which defines mpm_add_fuzzer (clang,
# -fsanitize=fuzzer,address,undefined, option MPM_FUZZ).
#   fuzz_lcm_sample: bytes as an LCM datagram on the sample, alarm and status
#                    channels (transport/lcm_wire.hpp), with a differential check
#                    against lcm-gen's decoder on what ours accepts
#   fuzz_dds_sample: bytes as the CDR body of a DDS Sample through Cyclone's
#                    normalize + read, then our limits check and copy
#                    (transport/dds_codec.hpp)
# Seeds: corpus/lcm_sample and corpus/dds_sample, written by make_wire_seeds
# (below; re-run it after changing transport/messages/) plus inputs the
# fuzzers found worth keeping.
mpm_add_fuzzer(lcm_sample
  SOURCE ${CMAKE_CURRENT_LIST_DIR}/fuzz_lcm_sample.cpp
  LIBS mpm_transport mpm_lcm_types
  CORPUS ${CMAKE_CURRENT_LIST_DIR}/corpus/lcm_sample)
mpm_add_fuzzer(dds_sample
  SOURCE ${CMAKE_CURRENT_LIST_DIR}/fuzz_dds_sample.cpp
  LIBS mpm_transport mpm_dds_types
  CORPUS ${CMAKE_CURRENT_LIST_DIR}/corpus/dds_sample)

# make_wire_seeds CORPUS_DIR: regenerates the committed seeds.
add_executable(make_wire_seeds ${CMAKE_CURRENT_LIST_DIR}/make_wire_seeds.cpp)
target_link_libraries(make_wire_seeds PRIVATE mpm_transport mpm_lcm_types mpm_dds_types)
target_include_directories(make_wire_seeds PRIVATE ${PROJECT_SOURCE_DIR} ${PROJECT_SOURCE_DIR}/tests)
