/* lsp_io.c — the base protocol's framing: header lines, a blank line, then
 * Content-Length bytes of JSON.
 *
 *   Content-Length: 52\r\n
 *   \r\n
 *   {"jsonrpc":"2.0","id":1,"method":"shutdown"}
 *
 * Bad input never stops the reader: a header block without a usable
 * Content-Length (missing, not a number, given twice differently, over
 * LSP_MAX_MESSAGE) is reported to the caller (-1) and reading goes on
 * with the next block; an over-long body is read and dropped; a header
 * line over 4 KiB is cut; bytes that are not headers are header lines
 * without a ':' (ignored).  Only the end of input ends it. */
#include "lsp.h"
#include "util.h"

#include <errno.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#define LINE_MAX_BYTES 4096
#define MAX_HEADER_LINES 64

struct lsp_reader {
    int    fd;
    char   buf[65536];
    size_t pos, end;      /* unread bytes: buf[pos..end) */
    bool   eof;
};

lsp_reader *lsp_reader_new(int fd)
{
    lsp_reader *r = xcalloc(1, sizeof *r);
    r->fd = fd;
    return r;
}

void lsp_reader_free(lsp_reader *r)
{
    free(r);
}

/* Refill an empty buffer; false at the end of input. */
static bool fill(lsp_reader *r)
{
    if (r->pos < r->end)
        return true;
    if (r->eof)
        return false;
    for (;;) {
        ssize_t n = read(r->fd, r->buf, sizeof r->buf);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            r->eof = true;
            return false;
        }
        r->pos = 0;
        r->end = (size_t)n;
        return true;
    }
}

bool lsp_pending(lsp_reader *r)
{
    if (r->pos < r->end)
        return true;
    if (r->eof)
        return false;
    struct pollfd p = { .fd = r->fd, .events = POLLIN };
    return poll(&p, 1, 0) > 0;
}

/* One header line without its "\r\n" or "\n", cut at LINE_MAX_BYTES - 1
 * (the rest is dropped).  False at the end of input. */
static bool read_line(lsp_reader *r, char *line, size_t *n)
{
    size_t o = 0;
    bool any = false;
    for (;;) {
        if (!fill(r)) {
            if (!any)
                return false;
            break;          /* a last line without its newline */
        }
        any = true;
        char c = r->buf[r->pos++];
        if (c == '\n')
            break;
        if (o < LINE_MAX_BYTES - 1)
            line[o++] = c;
    }
    if (o && line[o - 1] == '\r')
        o--;
    line[o] = 0;
    *n = o;
    return true;
}

/* Read (and keep, if body) `len` bytes; false at the end of input. */
static bool read_body(lsp_reader *r, char *body, size_t len)
{
    size_t got = 0;
    while (got < len) {
        if (!fill(r))
            return false;
        size_t k = r->end - r->pos;
        if (k > len - got)
            k = len - got;
        if (body)
            memcpy(body + got, r->buf + r->pos, k);
        r->pos += k;
        got += k;
    }
    return true;
}

/* " 123 " -> 123; false for anything else or over LSP_MAX_MESSAGE * 16. */
static bool parse_length(const char *s, unsigned long long *v)
{
    while (*s == ' ' || *s == '\t')
        s++;
    if (*s < '0' || *s > '9')
        return false;
    unsigned long long x = 0;
    for (; *s >= '0' && *s <= '9'; s++) {
        x = x * 10 + (unsigned)(*s - '0');
        if (x > (unsigned long long)LSP_MAX_MESSAGE * 16)
            return false;
    }
    while (*s == ' ' || *s == '\t')
        s++;
    if (*s)
        return false;
    *v = x;
    return true;
}

int lsp_read(lsp_reader *r, char **body, size_t *len, char *err, size_t n)
{
    char line[LINE_MAX_BYTES];
    size_t ll;
    unsigned long long length = 0;
    bool have = false, bad = false;
    int lines = 0;
    *body = NULL;
    *len = 0;
    /* skip blank lines between messages (a stray "\r\n" after a body) */
    do {
        if (!read_line(r, line, &ll))
            return 0;
    } while (ll == 0);
    for (;;) {
        lines++;
        char *colon = strchr(line, ':');
        if (colon && (size_t)(colon - line) == strlen("Content-Length") &&
            !strncasecmp(line, "Content-Length", (size_t)(colon - line))) {
            unsigned long long v;
            if (!parse_length(colon + 1, &v) || (have && v != length))
                bad = true;
            else
                length = v;
            have = true;
        }
        if (!read_line(r, line, &ll))
            return 0;
        if (ll == 0)
            break;
        if (lines >= MAX_HEADER_LINES) {
            /* not a header block: give up on it at the next blank line */
            bad = true;
        }
    }
    if (bad || !have) {
        snprintf(err, n, "%s", !have ? "a header block without Content-Length"
                               : "a bad Content-Length (not a number, too large, or "
                                 "given twice) or too many header lines");
        return -1;
    }
    if (length > LSP_MAX_MESSAGE) {
        snprintf(err, n, "a message of %llu bytes (at most %zu are read)", length,
                 LSP_MAX_MESSAGE);
        return read_body(r, NULL, (size_t)length) ? -1 : 0;
    }
    char *b = malloc((size_t)length + 1);
    if (!b) {
        snprintf(err, n, "out of memory for a message of %llu bytes", length);
        return read_body(r, NULL, (size_t)length) ? -1 : 0;
    }
    if (!read_body(r, b, (size_t)length)) {
        free(b);
        return 0;
    }
    b[length] = 0;
    *body = b;
    *len = (size_t)length;
    return 1;
}

bool lsp_write(FILE *out, const json_t *msg)
{
    char *s = json_dumps(msg, JSON_COMPACT | JSON_ENSURE_ASCII);
    if (!s)
        return false;
    size_t n = strlen(s);
    bool ok = fprintf(out, "Content-Length: %zu\r\n\r\n", n) > 0 &&
              fwrite(s, 1, n, out) == n && fflush(out) == 0;
    free(s);
    return ok;
}

/* ---- the server's messages --------------------------------------------- */

/* One message to the client (taken: freed here); a write failure is
 * reported on stderr. */
void lsp_send(lsp_server *s, json_t *msg)
{
    if (msg && !lsp_write(s->out, msg))
        fputs("splatc lsp: cannot write to standard output\n", stderr);
    json_decref(msg);
}
