// Must NOT compile: engine/ sits below render/.
#include "render/renderer.h"
int main() { return 0; }
