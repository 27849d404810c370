/* Embree 3 as the benchmarks' baseline (bench_traverse, bench_wide): one
 * single-threaded device, optionally limited to one instruction set, a scene
 * of the same triangles (RTC_BUILD_QUALITY_HIGH; optionally in Embree's robust
 * mode, RTC_SCENE_FLAG_ROBUST: conservative box tests and watertight
 * triangle tests, the like-for-like baseline of an exact tracer), and timed single-ray
 * queries over the same rays.  Include after bench_rays.h, and only with
 * CBVH_HAVE_EMBREE. */
#ifndef CBVH_BENCH_EMBREE_H
#define CBVH_BENCH_EMBREE_H

#include <embree3/rtcore.h>

/* threads=1, and isa=ISA when given; prints the configuration. */
static inline RTCDevice embree_device(const char *isa) {
    char config[64];
    snprintf(config, sizeof config, "threads=1%s%s", isa ? ",isa=" : "", isa ? isa : "");
    RTCDevice dev = rtcNewDevice(config);
    if (!dev) die("embree", "rtcNewDevice failed");
    printf("embree device: %s\n", config);
    return dev;
}

static inline RTCScene embree_scene(RTCDevice dev, const cbvh_scene *s, int robust) {
    RTCScene sc = rtcNewScene(dev);
    if (robust) rtcSetSceneFlags(sc, RTC_SCENE_FLAG_ROBUST);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                        (size_t)s->ntris * 3);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                           s->ntris);
    if (!vb || !ib) die("embree", "buffer allocation failed");
    for (uint32_t i = 0; i < s->ntris; i++)
        for (int k = 0; k < 3; k++) {
            for (int a = 0; a < 3; a++) vb[(size_t)9 * i + 3 * k + a] = s->tris[i].v[k][a];
            ib[(size_t)3 * i + k] = 3 * i + (unsigned)k;
        }
    rtcCommitGeometry(g);
    rtcAttachGeometry(sc, g);
    rtcReleaseGeometry(g);
    rtcSetSceneBuildQuality(sc, RTC_BUILD_QUALITY_HIGH);
    rtcCommitScene(sc);
    return sc;
}

/* n rays with rtcIntersect1 (closest) or rtcOccluded1 (any): seconds, and
 * the number of hits in *hits. */
static inline double embree_trace(RTCScene sc, const cbvh_ray *rays, int n, int occluded, long *hits) {
    long nh = 0;
    double t0 = now();
    for (int i = 0; i < n; i++) {
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        struct RTCRayHit rh;
        rh.ray.org_x = bf(rays[i].o[0]);
        rh.ray.org_y = bf(rays[i].o[1]);
        rh.ray.org_z = bf(rays[i].o[2]);
        rh.ray.dir_x = bf(rays[i].d[0]);
        rh.ray.dir_y = bf(rays[i].d[1]);
        rh.ray.dir_z = bf(rays[i].d[2]);
        rh.ray.tnear = 0;
        rh.ray.tfar = INFINITY;
        rh.ray.time = 0;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        if (occluded) {
            rtcOccluded1(sc, &ctx, &rh.ray);
            nh += rh.ray.tfar < 0;
        } else {
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(sc, &ctx, &rh);
            nh += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        }
    }
    *hits = nh;
    return now() - t0;
}

#endif
