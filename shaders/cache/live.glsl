// The radiance cache's list of live cells (graphs/radiance_cache.ron,
// `cache_live`): the update's indirect dispatch (its group counts), the
// number of cells listed, and their slots. cache/reset.comp empties it each
// frame, cache/sweep.comp fills it, cache/update.comp traces from it.
#ifndef WEFT_CACHE_LIVE_GLSL
#define WEFT_CACHE_LIVE_GLSL

// Invocations in one of the update's work groups (its local_size_x): 128,
// so the most cells (2048 x 2048) need 32,768 groups, within every
// device's 65,535.
#define CACHE_UPDATE_GROUP 128u

// The members of the buffer block each pass declares `cache_live` with.
#define CACHE_LIVE_MEMBERS \
    uint groups_x;         \
    uint groups_y;         \
    uint groups_z;         \
    uint count;            \
    uint slots[];

#endif
