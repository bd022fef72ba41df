// Sanitizer builds only (CLEARWAY_SANITIZE): LeakSanitizer's built-in suppressions, linked into the tool
// and every test program (the runtime looks for this function in the executable). Assimp 5.2 leaks
// what an importer had allocated when it throws on a malformed file (an ASCII STL facet with two
// vertices, a short COLLADA <matrix>, a garbage .x file): not ours to fix, and never on a file that
// loads. Only allocations made inside libassimp are suppressed; any leak of our own still fails.
extern "C" const char* __lsan_default_suppressions() { return "leak:libassimp.so\n"; }
