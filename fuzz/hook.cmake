# Included right after project() by fuzz/run.sh (CMAKE_PROJECT_brdf_factor_INCLUDE)
# while the top-level CMakeLists.txt does not add fuzz/ itself: adds it at the
# end of the top-level directory, once every library exists (include: a
# deferred call may not add a subdirectory).
cmake_language(DEFER DIRECTORY ${CMAKE_SOURCE_DIR} CALL include ${CMAKE_SOURCE_DIR}/fuzz/CMakeLists.txt)
