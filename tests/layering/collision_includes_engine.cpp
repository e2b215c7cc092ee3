// Must NOT compile: collision/ sits below engine/, so engine headers are not on its include path.
#include "engine/world.h"
int main() { return 0; }
