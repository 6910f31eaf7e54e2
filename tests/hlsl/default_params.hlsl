// Default parameter values: trailing arguments a call leaves out take them.
RWStructuredBuffer<float> results : register(u0);

static const uint SCALE_DEFAULT = 3;

// The default value sits on the prototype, as headers write it.
float scaled(float x, uint scale = SCALE_DEFAULT, float bias = 0.5);

float scaled(float x, uint scale, float bias)
{
    return x * scale + bias;
}

float3 offset(float3 p, float3 n, float eps = 1e-3)
{
    return p + n * eps;
}

struct Counter
{
    uint n;
    void bump(uint by = 1) { n += by; }
};

[numthreads(1, 1, 1)]
void Main()
{
    Counter c;
    c.n = 0;
    c.bump();
    c.bump(4);
    results[0] = scaled(2.0);          // 6.5
    results[1] = scaled(2.0, 1);       // 2.5
    results[2] = scaled(2.0, 1, 0.0);  // 2.0
    results[3] = offset(float3(0, 0, 0), float3(0, 1, 0)).y;
    results[4] = c.n;                  // 5
}
