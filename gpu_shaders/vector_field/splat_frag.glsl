/* Accumulated with additive blending: red sums the values, green counts them. */
void main()
{
  frag_color = vec4(value, 1.0, 0.0, 1.0);
}
