// Shared by every stage of the procedural probe pipeline.
struct Payload {
    uint kind;        // 0 miss, 1 triangle, 2 sphere
    uint primitive;
    uint custom;
    float t;
    uint any_hit_calls;
};
