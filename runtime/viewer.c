/* viewer.c — the GLFW window (being written). */
#include "splatrt.h"

int rt_viewer_run(const rt_viewer_desc *desc)
{
    (void)desc;
    fprintf(stderr, "splatview: the window viewer is not built yet; use --headless\n");
    return 1;
}
