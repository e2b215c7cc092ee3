// Must NOT compile: render/ sits below app/.
#include "run_scene.h"
int main() { return 0; }
