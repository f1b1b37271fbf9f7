# tetseg-bench (table): the paper's Table I over frame sequences; runtime only.
add_executable(tetseg-bench ${CMAKE_CURRENT_LIST_DIR}/bench_table.cpp)
target_link_libraries(tetseg-bench PRIVATE tetseg::runtime CLI11::CLI11)
tetseg_set_warnings(tetseg-bench)
