1LM=2
1 2
3 4
ID=crlf
