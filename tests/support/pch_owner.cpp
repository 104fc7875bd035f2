// Purpose: compiles the precompiled header (Eigen, Catch2) that every test executable reuses; the executable itself has no test case (Catch2's main from tf_test_support).
