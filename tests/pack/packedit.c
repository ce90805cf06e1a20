/* packedit — the corrupt-pack suite's editor (corrupt.sh): changes a
 * pack's manifest or writes a file, so each corruption is one line there.
 *
 *   packedit set MANIFEST PATH JSON     value at PATH ("a.b.0.c": object
 *                                       keys and array indices) := JSON
 *   packedit repeat MANIFEST PATH N     array at PATH := N copies of its
 *                                       first element
 *   packedit del MANIFEST PATH          the object key at PATH removed
 *   packedit png FILE W H               a W x H grey PNG
 *
 * The manifest is rewritten with jansson, indented as splatc writes it. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>
#include <stb_image_write.h>

static int usage(void)
{
    fprintf(stderr, "usage: packedit set|repeat MANIFEST PATH VALUE, packedit del MANIFEST PATH, "
            "packedit png FILE W H\n");
    return 2;
}

/* The parent of PATH's last part, and that part. */
static json_t *walk(json_t *root, char *path, char **last)
{
    json_t *cur = root;
    char *part = strtok(path, ".");
    for (;;) {
        char *next = strtok(NULL, ".");
        if (!next) {
            *last = part;
            return cur;
        }
        cur = json_is_array(cur) ? json_array_get(cur, (size_t)atoi(part))
                                 : json_object_get(cur, part);
        if (!cur)
            return NULL;
        part = next;
    }
}

static int set_at(json_t *parent, const char *key, json_t *v)
{
    if (json_is_array(parent))
        return json_array_set_new(parent, (size_t)atoi(key), v);
    return json_object_set_new(parent, key, v);
}

int main(int argc, char **argv)
{
    if (argc != 5 && !(argc == 4 && !strcmp(argv[1], "del")))
        return usage();
    if (!strcmp(argv[1], "png")) {
        int w = atoi(argv[3]), h = atoi(argv[4]);
        unsigned char *px = calloc((size_t)w * (size_t)h, 1);
        if (!px || w <= 0 || h <= 0)
            return 2;
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
            px[i] = (unsigned char)(i * 7);
        int ok = stbi_write_png(argv[2], w, h, 1, px, w);
        free(px);
        return ok ? 0 : 1;
    }
    json_error_t je;
    json_t *root = json_load_file(argv[2], 0, &je);
    if (!root) {
        fprintf(stderr, "packedit: %s: %s\n", argv[2], je.text);
        return 1;
    }
    char *last = NULL;
    json_t *parent = walk(root, argv[3], &last);
    if (!parent) {
        fprintf(stderr, "packedit: no such path\n");
        return 1;
    }
    int rc = 0;
    if (!strcmp(argv[1], "set")) {
        json_t *v = json_loads(argv[4], JSON_DECODE_ANY, &je);
        rc = v ? set_at(parent, last, v) : -1;
    } else if (!strcmp(argv[1], "del")) {
        rc = json_is_object(parent) ? json_object_del(parent, last) : -1;
    } else if (!strcmp(argv[1], "repeat")) {
        json_t *a = json_is_array(parent) ? json_array_get(parent, (size_t)atoi(last))
                                          : json_object_get(parent, last);
        json_t *first = json_array_get(a, 0);
        int n = atoi(argv[4]);
        rc = first ? 0 : -1;
        for (int i = (int)json_array_size(a); rc == 0 && i < n; i++)
            rc = json_array_append_new(a, json_deep_copy(first));
    } else {
        return usage();
    }
    if (rc == 0)
        rc = json_dump_file(root, argv[2], JSON_INDENT(2));
    json_decref(root);
    if (rc)
        fprintf(stderr, "packedit: cannot %s %s\n", argv[1], argv[3]);
    return rc ? 1 : 0;
}
