// Must NOT compile: render/ sits below app/.
#include "run_command.h"
int main() { return 0; }
