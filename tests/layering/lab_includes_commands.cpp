// Must NOT compile: the lab (app/lab/) sits below the commands (app/).
#include "command.h"
int main() { return 0; }
