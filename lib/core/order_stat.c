/* lib/core/order_stat.c — the k-th smallest of an array in linear expected
 * time (Hoare's selection with the median of three as pivot): a median or a
 * percentile of every edge in each embedding's report and bending weights,
 * where sorting 28K values cost 2-3 ms of a slider frame (face-study). */
#include "core/core_private.h"

static void swap(double *a, double *b)
{
    double t = *a;
    *a = *b;
    *b = t;
}

double es__kth_smallest(double *a, int64_t n, int64_t k)
{
    int64_t lo = 0, hi = n - 1;
    while (hi > lo) {
        /* the median of lo, mid, hi as the pivot, left at mid */
        int64_t mid = lo + (hi - lo) / 2;
        if (a[mid] < a[lo]) swap(a + mid, a + lo);
        if (a[hi] < a[lo]) swap(a + hi, a + lo);
        if (a[hi] < a[mid]) swap(a + hi, a + mid);
        double p = a[mid];
        int64_t i = lo, j = hi;
        while (i <= j) {
            while (a[i] < p) i++;
            while (p < a[j]) j--;
            if (i <= j) swap(a + i++, a + j--);
        }
        /* a[lo..j] <= p <= a[i..hi], and a[j+1..i-1] == p */
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else return a[k];
    }
    return a[k];
}
