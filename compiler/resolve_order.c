/* resolve_order.c — dependency order and cycles over a graph of nodes or
 * shaders: an iterative DFS (a 100 000-node chain cannot overflow the
 * stack), post-order, each back edge reported with its path. */
#include "resolve.h"
#include "util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Post-order (dependencies first) of every vertex; each back edge found
 * calls on_cycle with the path v0 -> … -> vk (-> v0).  Iterative. */
int *rs_dfs_order(const graph *g, cycle_fn on_cycle, void *user)
{
    int *order = malloc(((size_t)g->n + 1) * sizeof *order);
    int *state = calloc((size_t)g->n + 1, sizeof *state);
    int *pos = malloc(((size_t)g->n + 1) * sizeof *pos);      /* stack index */
    int *stack = malloc(((size_t)g->n + 1) * sizeof *stack);
    int *edge = malloc(((size_t)g->n + 1) * sizeof *edge);
    if (!order || !state || !pos || !stack || !edge)
        abort();
    int norder = 0;
    for (int root = 0; root < g->n; root++) {
        if (state[root])
            continue;
        int sp = 0;
        stack[sp] = root;
        edge[sp] = g->start[root];
        pos[root] = sp++;
        state[root] = 1;
        while (sp) {
            int v = stack[sp - 1];
            if (edge[sp - 1] < g->start[v + 1]) {
                int w = g->adj[edge[sp - 1]++];
                if (state[w] == 0) {
                    stack[sp] = w;
                    edge[sp] = g->start[w];
                    pos[w] = sp++;
                    state[w] = 1;
                } else if (state[w] == 1) {
                    on_cycle(user, stack + pos[w], sp - pos[w]);
                }
            } else {
                state[v] = 2;
                order[norder++] = v;
                sp--;
            }
        }
    }
    free(state);
    free(pos);
    free(stack);
    free(edge);
    return order;
}
