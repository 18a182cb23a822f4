LM=3
1 2
3 4
ID=x
