// Exits 0 where the CPU runs x86-64-v3 code (cmake/cpu_level.cmake).
int main() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("x86-64-v3") ? 0 : 1;
}
