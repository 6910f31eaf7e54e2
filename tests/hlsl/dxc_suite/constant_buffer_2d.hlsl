// A two-dimensional array of constant buffers: the descriptor array is an
// array of arrays of Block structs, and no array of Blocks has an
// ArrayStride.

struct Light {
    float4 color;
    int2 tile;
};

ConstantBuffer<Light> lights[2][3] : register(b0, space1);

float4 main(float2 uv : TEXCOORD) : SV_Target
{
    uint i = uint(uv.x * 2);
    return lights[1][0].color + lights[i][2].color * lights[0][i].tile.x;
}
